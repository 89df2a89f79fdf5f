#include "sheardiff/simulation.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "sheardiff/io/h5md.hpp"

namespace sheardiff {

namespace {

std::optional<Lubrication> lubrication_of(const Config& cfg) {
  if (!cfg.lubrication.enabled) return std::nullopt;
  return Lubrication{cfg.lubrication.delta, cfg.lubrication.h_max};
}

FrictionalContact contact_of(const Config& cfg) {
  const double kn = cfg.contact.ktilde;
  return FrictionalContact{kn, cfg.contact.kt_ratio * kn, cfg.contact.mu};
}

}  // namespace

double explicit_stability_dt(const Config& cfg) {
  // The fastest spring mode is the smallest pair (two small discs): its normal and slip
  // modes relax at rate k / R with R the dashpot (lubrication at contact) plus the drag.
  const double a = 0.5;
  const double drag = 3.0 * kPi * 2.0 * a / 2.0;  // relative motion of two drag-bound discs
  double rn = drag, rt = drag;
  if (auto lub = lubrication_of(cfg)) {
    const PairResistance r = lub->coefficients(a, a, 0.0);
    rn += r.xa;
    rt += r.ya;
  }
  const FrictionalContact c = contact_of(cfg);
  double dt = 2.0 * rn / c.kn;
  if (c.has_friction()) dt = std::min(dt, 2.0 * rt / c.kt);
  return dt;
}

Simulation::Simulation(const Config& cfg) : Simulation(cfg, build_scene(cfg)) {}

Simulation::Simulation(const Config& cfg, Scene scene)
    : cfg_(cfg), integrator_(make_integrator(cfg.integrator.type)) {
  StepLimits lim;
  lim.fixed_dt = cfg.integrator.dt;
  lim.max_displacement = cfg.integrator.max_displacement;
  lim.max_gap_fraction = cfg.integrator.max_gap_fraction;
  lim.max_overlap_change = cfg.integrator.max_overlap_change;
  lim.max_strain_step = cfg.integrator.max_strain_step;
  if (!integrator_->implicit_springs())
    lim.explicit_dt = cfg.integrator.explicit_safety * explicit_stability_dt(cfg);
  const double range = cfg.lubrication.enabled ? 1.0 + 0.5 * cfg.lubrication.h_max : 1.0;
  ForceBalance fb(lubrication_of(cfg), contact_of(cfg), 3, integrator_->implicit_springs());
  dynamics_ = std::make_unique<Dynamics>(std::move(scene.particles), scene.box, scene.flow,
                                         std::move(fb), NeighbourList(range, cfg.neighbour.skin),
                                         lim, std::move(scene.walls));
}

void Simulation::step() {
  if (!integrator_->step(*dynamics_))
    throw std::runtime_error(fmt::format(
        "linear solve failed at step {} (strain {:.6g}): the resistance matrix is not positive "
        "definite or the velocities are not finite",
        dynamics_->steps(), dynamics_->strain()));
}

namespace {

struct Averages {
  double weight = 0, sxy = 0, pressure = 0, contacts = 0, mean_overlap = 0;
  double max_overlap = 0;
  void add(const StressSample& s, double w) {
    weight += w;
    sxy += w * s.shear_stress();
    pressure += w * s.pressure();
    contacts += w * s.contacts;
    mean_overlap += w * s.mean_overlap;
    max_overlap = std::max(max_overlap, s.max_overlap);
  }
};

void write_text_atomically(const std::filesystem::path& file, const std::string& text) {
  const auto tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error(fmt::format("cannot write {}", tmp));
  }
  std::filesystem::rename(tmp, file);
}

}  // namespace

nlohmann::json run_to_directory(const Config& cfg, const std::filesystem::path& out_dir,
                                bool progress) {
  std::filesystem::create_directories(out_dir);
  const std::string resolved = to_toml(cfg);
  write_text_atomically(out_dir / "config.toml", resolved);

  Simulation sim(cfg);
  Dynamics& d = sim.dynamics();
  const Particles& p = d.particles();

  const std::vector<std::string> names = {"strain", "shear_stress", "pressure", "sigma_xx",
                                          "sigma_yy", "contacts", "max_overlap", "height"};
  std::unique_ptr<H5mdWriter> writer;
  if (cfg.output.trajectory) {
    TrajectoryLayout layout;
    layout.n_particles = p.size();
    layout.species = p.species;
    for (double a : p.radius) layout.diameter.push_back(2.0 * a);
    for (Motion m : p.motion) layout.motion.push_back(static_cast<int>(m));
    layout.lx = d.box().lx;
    layout.ly = d.box().ly;
    layout.lees_edwards = d.box().lees_edwards;
    layout.write_velocity = cfg.output.velocities;
    layout.observables = names;
    layout.creator_version = SHEARDIFF_VERSION;
    layout.config_toml = resolved;
    writer = std::make_unique<H5mdWriter>(out_dir / "trajectory.h5", layout);
  }

  const bool tty = progress && isatty(fileno(stderr));
  const auto t0 = std::chrono::steady_clock::now();
  auto last_print = t0;
  Averages avg;
  double next_frame = cfg.output.frame_strain;
  const double gd = cfg.flow.j;
  while (d.strain() < cfg.run.strain * (1.0 - 1e-12) &&
         (cfg.run.max_steps == 0 || d.steps() < cfg.run.max_steps)) {
    sim.step();
    const bool frame_due = d.strain() >= next_frame * (1.0 - 1e-12);
    const bool averaging = d.strain() > cfg.run.transient_strain;
    if (!frame_due && !averaging) continue;
    const StressSample s = sim.sample();
    if (averaging) avg.add(s, sim.integrator().last_dt());
    if (frame_due) {
      while (next_frame <= d.strain() * (1.0 + 1e-12)) next_frame += cfg.output.frame_strain;
      if (writer) {
        FrameData f;
        f.step = d.steps();
        f.time = d.time();
        f.lx = d.box().lx;
        f.ly = d.height();
        f.position = &p.position;
        f.unwrapped = &p.unwrapped;
        f.velocity = &sim.integrator().velocities().u;
        f.observables = {d.strain(), s.shear_stress(), s.pressure(), s.sxx, s.syy,
                         static_cast<double>(s.contacts), s.max_overlap, d.height()};
        writer->write_frame(f);
      }
    }
    if (tty) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_print > std::chrono::milliseconds(500)) {
        last_print = now;
        const double el = std::chrono::duration<double>(now - t0).count();
        const double eta = el * (cfg.run.strain - d.strain()) / std::max(d.strain(), 1e-12);
        std::fprintf(stderr, "\rstrain %.4g / %.4g  steps %ld  %.0f steps/s  ETA %.0f s   ",
                     d.strain(), cfg.run.strain, d.steps(), d.steps() / el, eta);
      }
    }
  }
  if (tty) std::fprintf(stderr, "\n");
  if (writer) writer->flush();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const double w = avg.weight > 0 ? avg.weight : 1.0;
  nlohmann::json js;
  js["scene"] = cfg.scene.type;
  js["N"] = cfg.particles.n;
  js["J"] = cfg.flow.j;
  js["ktilde"] = cfg.contact.ktilde;
  js["integrator"] = to_string(cfg.integrator.type);
  js["strain"] = d.strain();
  js["steps"] = d.steps();
  js["steps_per_strain"] = d.steps() / std::max(d.strain(), 1e-300);
  js["wall_seconds"] = wall;
  js["ms_per_step"] = 1e3 * wall / std::max<long>(d.steps(), 1);
  js["neighbour_rebuilds"] = d.neighbours().rebuilds();
  js["max_overlap"] = avg.max_overlap;
  js["mean_overlap"] = avg.mean_overlap / w;
  js["shear_stress"] = avg.sxy / w;
  js["pressure"] = avg.pressure / w;
  js["contacts_per_particle"] = avg.contacts / w / cfg.particles.n;
  js["viscosity"] = avg.sxy / w / gd;
  js["averaged_from_strain"] = cfg.run.transient_strain;
  js["lx"] = d.box().lx;
  js["ly"] = d.height();
  js["phi"] = [&] {
    double area = 0;
    for (std::size_t i = 0; i < p.n_mobile; ++i) area += kPi * p.radius[i] * p.radius[i];
    return area / (d.box().lx * d.height());
  }();
  write_text_atomically(out_dir / "summary.json", js.dump(2) + "\n");
  return js;
}

}  // namespace sheardiff
