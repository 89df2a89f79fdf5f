// Run time against error (issue 5, docs/model.md section 7): for the pressure-imposed plane shear
// at each (J, ktilde), one steady-ish starting state is made once (cached on disk), and from it
// every integrator (euler, heun, implicit) runs a short strain window with every step-size
// setting (adaptive with max displacement md, or a fixed dt). Each run is compared with the
// converged reference (implicit springs with the smallest step) over the same window:
//   rms_dev      rms distance of the mobile discs from the reference at the end of the window (d)
//   phi, mu      time averages over the window, and their differences to the reference
//   max_overlap  time average of the largest overlap, and its relative difference
// and reports wall seconds and steps per unit strain (wall time counts the steps only, not
// the measurements). Output: one CSV row per run; tools/plot_time_vs_error.py draws the front.
//
//   OMP_THREAD_LIMIT=1 build/bench/time_vs_error --out bench_results/time_vs_error.csv
//   OMP_THREAD_LIMIT=1 build/bench/time_vs_error --full --out bench_results/time_vs_error_full.csv
#include <fmt/format.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "sheardiff/observe/pressure_cell.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/solver/blas_kernels.hpp"

namespace {

using namespace sheardiff;

struct Grid {
  std::vector<double> j, ktilde, md, fixed_strain_step;
  double reference_md;
  // Explicit springs are held at their stability limit below max displacement ~ 3e-3 d in
  // every case of the grid, so smaller md only repeat the same run: the small grid skips them.
  std::vector<double> explicit_md;
};

// A step-size setting: adaptive (md > 0) or fixed dt = fixed_strain_step / J.
struct Setting {
  IntegratorType type;
  double md = 0.0;
  double fixed_strain_step = 0.0;
  bool reference = false;
};

struct Options {
  std::int64_t n = 250;
  std::int64_t seed = 1;
  double warmup = 1.0;     // strain before the starting state
  double window = 0.1;     // strain of each compared run
  double max_steps = 4e5;  // runs predicted (explicit) or found to need more are cut
  std::string cache = "bench_results/time_vs_error_cache";
  std::string out = "bench_results/time_vs_error.csv";
  bool full = false;
  std::string scene = "pressure_shear";
  double phi = 0.75;     // initial packing (simple_shear: the fixed area fraction)
  double mu = 0.5;       // Coulomb friction (0: frictionless, 2 unknowns per disc)
  double overlap = 0.0;  // > 0: max_overlap_change of every run (instead of md)
  double gap = 0.0;      // > 0: max_gap_fraction of every run (instead of 0.5 md / 1e-3)
};

Config base_config(const Options& o, double j, double ktilde) {
  Config c;
  c.scene.type = o.scene;
  c.particles.n = o.n;
  c.particles.phi_init = o.phi;
  c.flow.j = j;
  c.contact.ktilde = ktilde;
  c.run.seed = o.seed;
  c.contact.mu = o.mu;
  resolve_defaults(c);
  return c;
}

// Adaptive limits scaled together: md bounds the non-affine displacement and the overlap
// change per step, and the gap closing fraction scales with it from its default 0.5 at 1e-3.
void apply(Config& c, const Setting& s, const Options& o) {
  c.integrator.type = s.type;
  if (s.fixed_strain_step > 0.0) {
    c.integrator.dt = s.fixed_strain_step / c.flow.j;
  } else {
    c.integrator.max_displacement = s.md;
    c.integrator.max_overlap_change = s.md;
    c.integrator.max_gap_fraction = std::min(1.0, 0.5 * s.md / 1e-3);
  }
  if (o.overlap > 0.0) c.integrator.max_overlap_change = o.overlap;
  if (o.gap > 0.0) c.integrator.max_gap_fraction = o.gap;
}

// CPU time of this process: on a machine shared with other jobs it measures the work, where
// wall time also counts the waits for a core.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::string tag(double x) {
  return fmt::format("{:.0e}", x);
}

// The starting state of (J, ktilde): made once by an implicit run over the warm-up strain from
// the random packing, then read back from the cache.
std::vector<char> starting_state(const Options& o, const Config& c, const Scene& scene) {
  namespace fs = std::filesystem;
  const fs::path file =
      fs::path(o.cache) / fmt::format("start_{}_phi{}_mu{}_N{}_J{}_k{}_seed{}_w{}.bin", o.scene,
                                      o.phi, o.mu, o.n, tag(c.flow.j), tag(c.contact.ktilde),
                                      o.seed, o.warmup);
  if (fs::exists(file)) {
    std::ifstream in(file, std::ios::binary);
    return std::vector<char>(std::istreambuf_iterator<char>(in), {});
  }
  const auto t0 = std::chrono::steady_clock::now();
  Simulation sim(c, scene);
  while (sim.dynamics().strain() < o.warmup) sim.step();
  Archive a = Archive::writer();
  sim.dynamics().serialize(a);
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary)
      .write(a.bytes().data(), static_cast<std::streamsize>(a.bytes().size()));
  std::cerr << fmt::format(
      "  starting state J={} ktilde={}: {} steps, {:.1f} s -> {}\n", c.flow.j, c.contact.ktilde,
      sim.dynamics().steps(),
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), file.string());
  return a.bytes();
}

struct Result {
  Setting setting;
  std::string status = "ok";
  long steps = 0;
  double strain = 0.0, wall = 0.0, cpu = 0.0;
  std::vector<Vec2> end;  // mobile unwrapped positions at exactly the end of the window
  double phi = 0.0, mu = 0.0, overlap = 0.0;
  std::string limited_by;
};

Result run(const Options& o, Config c, const Scene& scene, const std::vector<char>& start,
           const Setting& s) {
  apply(c, s, o);
  Result r;
  r.setting = s;
  // Explicit springs need about window / (J dt_stab) steps: skip what cannot finish.
  if (c.integrator.type != IntegratorType::Implicit && s.fixed_strain_step == 0.0) {
    const double est =
        o.window / (c.flow.j * c.integrator.explicit_safety * explicit_stability_dt(c));
    if (est > o.max_steps) {
      r.status = fmt::format("skipped: ~{:.2g} steps", est);
      return r;
    }
  }
  Simulation sim(c, scene);
  Archive a = Archive::reader(start);
  sim.dynamics().serialize(a);
  Dynamics& d = sim.dynamics();
  const Particles& p = d.particles();
  const double s0 = d.strain(), target = s0 + o.window, lx = d.box().lx * c.flow.lz;
  const bool walls = d.walls().has_value();
  const long steps0 = d.steps();
  const auto limits0 = d.step_limit_counts();
  std::vector<Vec2> prev(p.unwrapped.begin(), p.unwrapped.begin() + p.n_mobile);
  double prev_strain = s0, weight = 0.0;
  try {
    while (d.strain() < target) {
      if (d.steps() - steps0 >= o.max_steps) {
        r.status = "cut at max_steps";
        break;
      }
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpu_seconds();
      sim.step();
      r.cpu += cpu_seconds() - c0;
      r.wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const StressSample st = sim.sample();
      const double w = d.strain() - prev_strain;
      if (!std::isfinite(st.max_overlap) || !std::isfinite(st.top_wall_fx))
        throw std::runtime_error("non-finite state");
      // Simple shear: phi is fixed and mu is the particle shear stress over the pressure.
      r.phi += w * (walls ? PressureCellObserver::bulk_phi(d, c.observables.wall_exclusion)
                          : c.particles.phi_init);
      r.mu += w * (walls ? -st.top_wall_fx / lx : st.shear_stress() / st.pressure());
      r.overlap += w * st.max_overlap;
      weight += w;
      if (d.strain() >= target) {
        const double f = (target - prev_strain) / (d.strain() - prev_strain);
        r.end.resize(p.n_mobile);
        for (std::size_t i = 0; i < p.n_mobile; ++i)
          r.end[i] = prev[i] + f * (p.unwrapped[i] - prev[i]);
      } else {
        std::copy(p.unwrapped.begin(), p.unwrapped.begin() + p.n_mobile, prev.begin());
        prev_strain = d.strain();
      }
    }
  } catch (const std::exception& e) {
    r.status = fmt::format("failed: {}", e.what());
  }
  r.steps = d.steps() - steps0;
  r.strain = d.strain() - s0;
  if (weight > 0.0) r.phi /= weight, r.mu /= weight, r.overlap /= weight;
  long best = -1;
  for (int k = 0; k < static_cast<int>(StepLimit::Count); ++k) {
    const long n = d.step_limit_counts()[k] - limits0[k];
    if (n > best)
      best = n, r.limited_by = fmt::format("{} {:.0f}%", to_string(static_cast<StepLimit>(k)),
                                           100.0 * n / std::max(1L, r.steps));
  }
  return r;
}

double rms_deviation(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  if (a.empty() || a.size() != b.size()) return NAN;
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]).squaredNorm();
  return std::sqrt(s / a.size());
}

}  // namespace

int main(int argc, char** argv) {
  sheardiff::set_solver_environment(argv);  // as sheardiff runs (blas_kernels.hpp)
  CLI::App app{"Run time against error of every integrator and step-size setting"};
  Options o;
  app.add_flag("--full", o.full, "Full grid: J in {1e-1..1e-4}, ktilde in {1e3, 1e4, 1e5}");
  app.add_option("--N", o.n, "Mobile discs");
  app.add_option("--seed", o.seed, "Seed of the packing");
  app.add_option("--warmup", o.warmup, "Strain run to make each starting state");
  app.add_option("--window", o.window, "Strain of each compared run");
  app.add_option("--max-steps", o.max_steps, "Cut (or skip) runs needing more steps");
  app.add_option("--cache", o.cache, "Folder of the cached starting states");
  app.add_option("--out", o.out, "CSV file");
  app.add_option("--scene", o.scene, "pressure_shear (default) or simple_shear")
      ->check(CLI::IsMember({"pressure_shear", "simple_shear"}));
  app.add_option("--mu", o.mu, "Coulomb friction coefficient");
  app.add_option("--overlap", o.overlap, "Fix max_overlap_change (d) in every run");
  app.add_option("--gap", o.gap, "Fix max_gap_fraction in every run");
  app.add_option("--phi", o.phi, "Initial area fraction (simple_shear: the fixed one)");
  std::vector<double> only_j, only_k, only_md, only_fixed;
  std::vector<std::string> only_types;
  app.add_option("--J", only_j, "Override the J values");
  app.add_option("--ktilde", only_k, "Override the ktilde values");
  app.add_option("--md", only_md, "Override the adaptive max displacements (d)");
  app.add_option("--fixed", only_fixed, "Override the fixed strain steps (J dt); 0 = none");
  app.add_option("--integrators", only_types, "Only these integrators (euler heun implicit)");
  double reference_md = 0.0;
  app.add_option("--reference-md", reference_md, "Max displacement of the reference run");
  CLI11_PARSE(app, argc, argv);

  Grid g;
  if (o.full) {
    g = {{1e-1, 1e-2, 1e-3, 1e-4}, {1e3, 1e4, 1e5}, {3e-3, 1e-3, 3e-4}, {1e-3, 1e-4, 1e-5}, 1e-4,
         {3e-3, 1e-3, 3e-4}};
  } else {
    g = {{1e-2, 1e-3, 1e-4}, {1e4}, {3e-3, 1e-3, 3e-4}, {1e-3, 1e-4}, 1e-4, {1e-3}};
  }
  if (!only_j.empty()) g.j = only_j;
  if (!only_k.empty()) g.ktilde = only_k;
  if (!only_md.empty()) g.md = g.explicit_md = only_md;
  if (!only_fixed.empty()) {
    g.fixed_strain_step.clear();
    for (double f : only_fixed)
      if (f > 0.0) g.fixed_strain_step.push_back(f);
  }
  if (reference_md > 0.0) g.reference_md = reference_md;
  std::vector<IntegratorType> types{IntegratorType::Euler, IntegratorType::Heun,
                                    IntegratorType::Implicit};
  if (!only_types.empty()) {
    types.clear();
    for (const auto& t : only_types)
      types.push_back(t == "euler"  ? IntegratorType::Euler
                      : t == "heun" ? IntegratorType::Heun
                                    : IntegratorType::Implicit);
  }

  std::filesystem::create_directories(std::filesystem::path(o.out).parent_path().empty()
                                          ? "."
                                          : std::filesystem::path(o.out).parent_path());
  std::ofstream csv(o.out);
  csv << "scene,mu,N,J,ktilde,integrator,policy,md,strain_step,window,status,steps,steps_per_"
         "strain,"
         "wall_s,wall_s_per_strain,ms_per_step,cpu_s_per_strain,cpu_ms_per_step,rms_dev,phi,mu,max_"
         "overlap,phi_err,mu_err,"
         "overlap_rel_err,limited_by\n";
  for (double ktilde : g.ktilde) {
    for (double j : g.j) {
      const Config c = base_config(o, j, ktilde);
      const Scene scene = build_scene(c);
      const std::vector<char> start = starting_state(o, c, scene);
      std::vector<Setting> settings;
      settings.push_back({IntegratorType::Implicit, g.reference_md, 0.0, true});
      for (IntegratorType t : types) {
        for (double md : t == IntegratorType::Implicit ? g.md : g.explicit_md)
          settings.push_back({t, md, 0.0, false});
        for (double fs : g.fixed_strain_step) settings.push_back({t, 0.0, fs, false});
      }
      std::optional<Result> ref;
      for (const Setting& s : settings) {
        const Result r = run(o, c, scene, start, s);
        if (s.reference) ref = r;
        const bool ok = r.status == "ok";
        const double rms = ok && ref ? rms_deviation(r.end, ref->end) : NAN;
        const std::string policy = s.reference               ? "reference"
                                   : s.fixed_strain_step > 0 ? "fixed"
                                                             : "adaptive";
        const std::string row = fmt::format(
            "{},{:g},{},{:g},{:g},{},{},{:g},{:g},{:g},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:."
            "6g},{:.6g},{:.8g},{:.8g},"
            "{:.6g},{:.6g},{:.6g},{:.6g},{}",
            o.scene, o.mu, o.n, j, ktilde, to_string(s.type), policy, s.md, s.fixed_strain_step,
            o.window, r.status, r.steps, r.strain > 0 ? r.steps / r.strain : NAN, r.wall,
            r.strain > 0 ? r.wall / r.strain : NAN, r.steps ? 1e3 * r.wall / r.steps : NAN,
            r.strain > 0 ? r.cpu / r.strain : NAN, r.steps ? 1e3 * r.cpu / r.steps : NAN, rms,
            ok ? r.phi : NAN, ok ? r.mu : NAN, ok ? r.overlap : NAN, ok ? r.phi - ref->phi : NAN,
            ok ? r.mu - ref->mu : NAN, ok ? r.overlap / ref->overlap - 1.0 : NAN, r.limited_by);
        csv << row << "\n" << std::flush;
        std::cerr << row << "\n";
      }
    }
  }
  return 0;
}
