#include "sheardiff/simulation.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>

#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/observe/observer.hpp"
#include "sheardiff/observe/pressure_cell.hpp"
#include "sheardiff/observe/run_health.hpp"
#include "sheardiff/observe/stress.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {

namespace {

std::optional<Lubrication> lubrication_of(const Config& cfg) {
  if (!cfg.lubrication.enabled) return std::nullopt;
  return Lubrication{cfg.lubrication.delta, cfg.lubrication.h_max, cfg.lubrication.tangential};
}

FrictionalContact contact_of(const Config& cfg) {
  const double kn = cfg.contact.ktilde;
  return FrictionalContact{kn, cfg.contact.kt_ratio * kn, cfg.contact.mu,
                           cfg.contact.stiffness == "mean_radius"};
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

bool rotational_unknowns(const Config& cfg) {
  if (cfg.solver.rotations == "always") return true;
  // Rotation couples to translation only through friction and the tangential lubrication modes
  // (which include the contact dashpots); without both, omega = omega_inf + T_ext / drag.
  const bool tangential_lubrication = cfg.lubrication.enabled && cfg.lubrication.tangential;
  return contact_of(cfg).has_friction() || tangential_lubrication;
}

void validate_run_inputs(const Config& cfg, const std::string& origin) {
  if (cfg.integrator.type != IntegratorType::Implicit && cfg.integrator.dt > 0.0) {
    const double limit = explicit_stability_dt(cfg);
    if (cfg.integrator.dt >= limit)
      throw ConfigError(fmt::format(
          "{}: integrator.dt: fixed dt = {} is not below the stability limit 2 R/k = {:.3g} "
          "eta/P of explicit springs (smallest pair, normal and slip modes, "
          "model.md section 7; integrator.type = \"{}\", contact.ktilde = {}); use integrator.dt < "
          "{:.3g}, integrator.dt = 0 (adaptive), or "
          "integrator.type = \"implicit\"",
          origin, cfg.integrator.dt, limit, to_string(cfg.integrator.type), cfg.contact.ktilde,
          limit));
  }
  if (!cfg.particles.init_file.empty()) {
    try {
      (void)initial_packing(cfg);
    } catch (const ConfigError& e) {
      throw ConfigError(fmt::format("{}: {}", origin, e.what()));
    } catch (const std::exception& e) {
      throw ConfigError(fmt::format("{}: particles.init_file: {}", origin, e.what()));
    }
  }
}

Simulation::Simulation(const Config& cfg) : Simulation(cfg, build_scene(cfg)) {}

Simulation::Simulation(const Config& cfg, Scene scene)
    : cfg_(cfg), integrator_(make_integrator(cfg.integrator.type)) {
  StepLimits lim;
  lim.fixed_dt = cfg.integrator.dt;
  lim.max_displacement = cfg.integrator.max_displacement;
  lim.max_gap_fraction = cfg.integrator.max_gap_fraction;
  lim.max_overlap_change = overlap_change_limit(cfg);
  lim.max_strain_step = cfg.integrator.max_strain_step;
  lim.end_time = cfg.run.strain / cfg.flow.j;
  if (!integrator_->implicit_springs())
    lim.explicit_dt = cfg.integrator.explicit_safety * explicit_stability_dt(cfg);
  const double range = cfg.lubrication.enabled ? 1.0 + 0.5 * cfg.lubrication.h_max : 1.0;
  ForceBalance fb(lubrication_of(cfg), contact_of(cfg), rotational_unknowns(cfg) ? 3 : 2,
                  integrator_->implicit_springs(), cfg.solver.cholesky);
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

// Only the observers the scene and the config ask for are composed into the run.
std::vector<std::unique_ptr<Observer>> make_observers(const Config& cfg,
                                                      const std::filesystem::path& out_dir) {
  std::vector<std::unique_ptr<Observer>> obs;
  obs.push_back(std::make_unique<RheologyObserver>(cfg.run.transient_strain));
  std::function<bool(const Dynamics&)> measuring;
  if (cfg.scene.type == "pressure_shear") {
    auto cell = std::make_unique<PressureCellObserver>(cfg);
    const PressureCellObserver* c = cell.get();
    measuring = [c](const Dynamics&) { return c->steady(); };
    obs.push_back(std::move(cell));
  } else {
    const double from = cfg.run.transient_strain;
    measuring = [from](const Dynamics& d) { return d.strain() > from; };
  }
  if (cfg.analysis.diffusion)
    obs.push_back(std::make_unique<DiffusionObserver>(cfg, out_dir / "analysis.h5", measuring));
  return obs;
}

namespace {

std::atomic<int> g_stop_signal{0};
extern "C" void on_stop_signal(int sig) {
  g_stop_signal.store(sig);
}

// Installs SIGINT/SIGTERM handlers for the lifetime of a run and restores the old ones.
struct StopSignals {
  struct sigaction old_int {
  }, old_term{};
  StopSignals() {
    g_stop_signal.store(0);
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
  }
};

// 2: the run health state was added.
constexpr const char* kCheckpointMagic = "sheardiff-checkpoint-2";

std::vector<char> read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot read the checkpoint", file.string()));
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

nlohmann::json run_to_directory(const Config& given, const std::filesystem::path& out_dir,
                                bool progress, bool resume) {
  Config cfg = given;
  resolve_defaults(cfg);
  const std::string resolved = to_toml(cfg);
  const auto checkpoint_file = out_dir / "checkpoint.bin";
  std::vector<char> checkpoint;
  if (resume) {
    if (!std::filesystem::exists(checkpoint_file))
      throw ConfigError(fmt::format("--resume {}: no checkpoint.bin there", out_dir.string()));
    checkpoint = read_bytes(checkpoint_file);
  }
  // The initial state is built before anything is written: a bad input file leaves no output.
  Simulation sim(cfg);
  Dynamics& d = sim.dynamics();
  const Particles& p = d.particles();
  // The residual is one sparse product per solve, small next to the factorisation.
  d.force_balance().set_check_residual(true);
  RunHealth health(cfg, d);
  if (!resume) {
    std::filesystem::create_directories(out_dir);
    std::filesystem::remove(checkpoint_file);
    std::filesystem::remove(out_dir / "summary.json");
    std::filesystem::remove(out_dir / "diagnostic.txt");
    write_file_atomically(out_dir / "config.toml", resolved);
  }
  auto observers = make_observers(cfg, out_dir);

  double next_frame = cfg.output.frame_strain;
  double next_checkpoint = cfg.output.checkpoint_strain;
  double elapsed_before = 0.0;
  long frames = 0;
  // The whole evolving state of the run, in one fixed order for saving and loading.
  const auto serialize = [&](Archive& a) {
    std::string magic = kCheckpointMagic, config = resolved;
    a.io(magic);
    if (magic != kCheckpointMagic)
      throw std::runtime_error("checkpoint: not a sheardiff checkpoint");
    a.io(config);
    if (config != resolved)
      throw ConfigError(fmt::format(
          "--resume {}: the configuration differs from the one the checkpoint was written with "
          "(see {}/config.toml)",
          out_dir.string(), out_dir.string()));
    d.serialize(a);
    sim.serialize_integrator(a);
    for (auto& o : observers) o->serialize(a);
    health.serialize(a);
    a.io(next_frame), a.io(next_checkpoint), a.io(elapsed_before), a.io(frames);
  };
  if (resume) {
    Archive a = Archive::reader(std::move(checkpoint));
    serialize(a);
  }

  std::vector<std::string> names, units;
  for (const auto& o : observers) {
    for (auto& n : o->frame_names()) names.push_back(n);
    for (auto& u : o->frame_units()) units.push_back(u);
  }
  std::unique_ptr<H5mdWriter> writer;
  if (cfg.output.trajectory) {
    TrajectoryLayout layout;
    layout.n_particles = p.size();
    layout.species = p.species;
    for (double a : p.radius) layout.diameter.push_back(2.0 * a);
    for (Motion m : p.motion) layout.motion.push_back(static_cast<int>(m));
    layout.lx = d.box().lx;
    layout.ly = d.height();
    layout.lees_edwards = d.box().lees_edwards;
    layout.write_velocity = cfg.output.velocities;
    layout.observables = names;
    layout.observable_units = units;
    layout.write_contacts = cfg.output.contacts;
    layout.author = cfg.output.author;
    layout.creator_version = SHEARDIFF_VERSION;
    layout.config_toml = resolved;
    const auto file = out_dir / "trajectory.h5";
    writer = resume ? std::make_unique<H5mdWriter>(H5mdWriter::resume(file, layout, frames))
                    : std::make_unique<H5mdWriter>(file, layout);
  }
  const auto save_checkpoint = [&](double elapsed_now) {
    if (writer) writer->flush();  // the trajectory holds every frame the checkpoint counts
    Archive a = Archive::writer();
    double total = elapsed_before + elapsed_now;
    std::swap(total, elapsed_before);
    serialize(a);
    std::swap(total, elapsed_before);
    // Whole or absent: a checkpoint is never half-written.
    write_file_atomically(checkpoint_file, a.bytes().data(), a.bytes().size());
  };

  StopSignals signals;
  const bool tty = progress && isatty(fileno(stderr));
  const auto t0 = std::chrono::steady_clock::now();
  const auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  auto last_print = t0, last_flush = t0;
  std::vector<double> values;
  const auto finished = [&] {
    for (const auto& o : observers)
      if (o->done(d)) return true;
    return d.strain() >= cfg.run.strain * (1.0 - 1e-12) ||
           (cfg.run.max_steps > 0 && d.steps() >= cfg.run.max_steps);
  };
  // A run gone wrong stops with a checkpoint if its state is finite (else the last one is
  // kept) and a diagnostic frame.
  const auto stop = [&](const HealthReport& r) {
    if (r.state_finite) save_checkpoint(seconds());
    write_diagnostic(out_dir / "diagnostic.txt", d, sim.integrator().velocities(), r);
    if (tty) std::fprintf(stderr, "\n");
    throw RunUnhealthy(r);
  };
  while (!finished()) {
    if (const int sig = g_stop_signal.load()) {
      save_checkpoint(seconds());
      if (tty) std::fprintf(stderr, "\n");
      throw RunInterrupted(
          sig,
          fmt::format(
              "stopped by signal {} at step {} (strain {:.6g}); checkpoint written: resume with "
              "`sheardiff run CONFIG --resume {}`",
              sig, d.steps(), d.strain(), out_dir.string()));
    }
    if (!sim.try_step()) stop(health.solver_failure(d, sim.integrator().velocities()));
    if (auto r = health.check(d, sim.integrator().velocities(), sim.integrator().last_dt()))
      stop(*r);
    const StressSample s = sim.sample();
    const StepView view{d, sim.integrator().velocities(), s, sim.integrator().last_dt()};
    for (const auto& o : observers) o->on_step(view);
    if (d.strain() >= next_frame * (1.0 - 1e-12)) {
      while (next_frame <= d.strain() * (1.0 + 1e-12)) next_frame += cfg.output.frame_strain;
      values.clear();
      for (const auto& o : observers) o->on_frame(view, values);
      if (writer) {
        FrameData f;
        f.step = d.steps();
        f.time = d.time();
        f.lx = d.box().lx;
        f.ly = d.height();
        f.tilt = d.box().le_offset;
        f.position = &p.position;
        f.unwrapped = &p.unwrapped;
        f.velocity = &sim.integrator().velocities().u;
        f.observables = values;
        ContactNetwork contacts;
        if (cfg.output.contacts) contacts = contact_network(d);
        f.contacts = &contacts;
        writer->write_frame(f);
      }
      ++frames;
      if (cfg.output.checkpoint_strain > 0.0 && d.strain() >= next_checkpoint * (1.0 - 1e-12)) {
        while (next_checkpoint <= d.strain() * (1.0 + 1e-12))
          next_checkpoint += cfg.output.checkpoint_strain;
        save_checkpoint(seconds());
      }
    }
    const auto now = std::chrono::steady_clock::now();
    // A terminal gets a live line; a batch log gets one line a minute. The trajectory is
    // flushed every half minute so that a killed run leaves readable frames behind.
    const auto since = now - last_print;
    if ((tty && since > std::chrono::milliseconds(500)) ||
        (!tty && progress && since > std::chrono::seconds(60))) {
      last_print = now;
      const double el = std::chrono::duration<double>(now - t0).count();
      // A pressure cell that has found its steady state stops at steady + measure_strain.
      double end = cfg.run.strain;
      for (const auto& o : observers) end = std::min(end, o->planned_end_strain());
      const double eta = el * std::max(end - d.strain(), 0.0) / std::max(d.strain(), 1e-12);
      std::fprintf(stderr, "%sstrain %.4g / %.4g  steps %ld  %.0f steps/s  ETA %.0f s%s",
                   tty ? "\r" : "", d.strain(), end, d.steps(), d.steps() / el, eta,
                   tty ? "   " : "\n");
    }
    if (writer && now - last_flush > std::chrono::seconds(30)) {
      writer->flush();
      last_flush = now;
    }
  }
  // The last move may have used up the skin: check it against a fresh neighbour list.
  if (d.neighbours().needs_rebuild()) {
    d.rebuild_now();
    if (auto r = health.check(d, sim.integrator().velocities(), sim.integrator().last_dt()))
      stop(*r);
  }
  if (tty) std::fprintf(stderr, "\n");
  const double wall = elapsed_before + seconds();

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
  js["ms_per_step"] = 1e3 * wall / static_cast<double>(std::max<long>(d.steps(), 1));
  js["neighbour_rebuilds"] = d.neighbours().rebuilds();
  js["factorisations"] = d.force_balance().system().factorisations();
  {
    // Which limit set the steps: where the step count comes from.
    nlohmann::json by;
    const auto& counts = d.step_limit_counts();
    for (int k = 0; k < static_cast<int>(StepLimit::Count); ++k)
      if (counts[k] > 0)
        by[to_string(static_cast<StepLimit>(k))] =
            static_cast<double>(counts[k]) / static_cast<double>(std::max<long>(d.steps(), 1));
    js["dt_limited_by"] = by;
  }
  js["lx"] = d.box().lx;
  js["ly"] = d.height();
  for (const auto& o : observers) o->finish(d, js, writer.get());
  health.report(js);
  if (!js.contains("phi")) {
    double area = 0;
    for (std::size_t i = 0; i < p.n_mobile; ++i) area += kPi * p.radius[i] * p.radius[i];
    js["phi"] = area / (d.box().lx * d.height());
  }
  if (writer) writer->flush();
  writer.reset();
  write_file_atomically(out_dir / "summary.json", js.dump(2) + "\n");
  // Finished: the summary marks the run complete and the checkpoint has served its purpose.
  std::filesystem::remove(checkpoint_file);
  return js;
}

}  // namespace sheardiff
