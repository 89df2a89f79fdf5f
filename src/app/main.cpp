// Command line of sheardiff: run a config, validate one, or print the config reference.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <iostream>

#include "sheardiff/config.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/observe/run_health.hpp"
#include "sheardiff/simulation.hpp"
#include <cmath>

namespace {
// Exit codes (README, docs/stability.md): 0 done, 2 invalid config or input, 3 the run failed
// numerically outside the step loop, 4 stopped by a run health check (kExitUnhealthy), 1
// anything else (I/O), 128 + signal after SIGINT/SIGTERM.
constexpr int kExitConfig = 2;
constexpr int kExitNumerical = 3;

// A summary value, NaN when absent or not a number: summaries of older versions or of runs
// that ended early lack some keys, and printing must not abort on them.
double num(const nlohmann::json& js, const char* key) {
  const auto it = js.find(key);
  return it != js.end() && it->is_number() ? it->get<double>() : NAN;
}
double num_at(const nlohmann::json& js, const char* key, std::size_t i) {
  const auto it = js.find(key);
  return it != js.end() && it->is_array() && i < it->size() && (*it)[i].is_number()
             ? (*it)[i].get<double>()
             : NAN;
}
void print_warnings(const nlohmann::json& js) {
  const auto it = js.find("analysis_warnings");
  if (it == js.end() || !it->is_array()) return;
  for (const auto& w : *it)
    if (w.is_string()) fmt::print(stderr, "warning: {}\n", w.get<std::string>());
}
}  // namespace

int main(int argc, char** argv) {
  // CHOLMOD (Debian's build) opens OpenMP regions with a fixed num_threads clause inside its
  // supernodal factorisation; only OMP_THREAD_LIMIT, read when libgomp loads, caps them. Spare
  // threads spin and cost a shared 2-core machine ~40%, and sweeps already run one process per
  // core, so sheardiff runs single-threaded unless the caller sets OMP_THREAD_LIMIT itself
  // (docs/performance.md). Setting it needs a fresh process image: re-execute once.
  if (std::getenv("OMP_THREAD_LIMIT") == nullptr) {
    setenv("OMP_THREAD_LIMIT", "1", 1);
    execv("/proc/self/exe", argv);  // returns only on failure: then run as we are
  }
  CLI::App app{"sheardiff: overdamped frictional DEM of dense non-Brownian suspensions"};
  app.require_subcommand(1);

  std::string config_path, out_dir = "out";
  std::vector<std::string> overrides;

  auto* run = app.add_subcommand("run", "Run a configuration to its end");
  run->add_option("config", config_path, "Configuration file (TOML, see docs/config.md)")
      ->required();
  run->add_option("--out", out_dir,
                  "Output folder: trajectory.h5 (H5MD), summary.json, config.toml")
      ->capture_default_str();
  run->add_option("--set", overrides,
                  "Override one key, section.key=value (repeatable), e.g. --set flow.J=1e-3");
  std::string resume_dir;
  run->add_option("--resume", resume_dir,
                  "Continue the run in DIR from its checkpoint.bin (same CONFIG and --set); the "
                  "trajectory is cut back to the checkpoint, the result is bit-identical to an "
                  "uninterrupted run");

  auto* check = app.add_subcommand("check", "Validate a configuration and print it resolved");
  check->add_option("config", config_path, "Configuration file (TOML)")->required();
  check->add_option("--set", overrides, "Override one key, section.key=value (repeatable)");

  auto* doc = app.add_subcommand("config-doc", "Print the reference table of every config key");

  std::string run_dir;
  auto* analyse = app.add_subcommand(
      "analyse", "Recompute the diffusion analysis (MSD, D, dv, VACF, Psi) of a finished run "
                 "from DIR/trajectory.h5 alone; rewrites DIR/analysis.h5 and summary.json");
  analyse->add_option("dir", run_dir, "Run directory")->required();

  CLI11_PARSE(app, argc, argv);

  try {
    if (doc->parsed()) {
      std::cout << sheardiff::config_reference_markdown();
      return 0;
    }
    if (analyse->parsed()) {
      const auto js = sheardiff::reanalyse_run(run_dir);
      fmt::print("{}: D = {:.4g} +- {:.2g} gammadot d^2 over strain window [{:g}, {:g}] "
                 "(log-log slope {:.3f}); dv = {:.4g} gammadot d; Psi = {:.4g} / gammadot; "
                 "step length {:.4g} d\n",
                 run_dir, num(js, "D"), num(js, "D_stderr"), num_at(js, "msd_window", 0),
                 num_at(js, "msd_window", 1), num(js, "msd_window_slope"), num(js, "dv"),
                 num(js, "psi"), num(js, "step_length"));
      print_warnings(js);
      return 0;
    }
    const sheardiff::Config cfg = sheardiff::load_config(config_path, overrides);
    sheardiff::validate_run_inputs(cfg, config_path);
    if (check->parsed()) {
      std::cout << sheardiff::to_toml(cfg);
      return 0;
    }
    const bool resume = !resume_dir.empty();
    if (resume) out_dir = resume_dir;
    const auto summary = sheardiff::run_to_directory(cfg, out_dir, true, resume);
    const auto flag = [&](const char* key) {
      const auto it = summary.find(key);
      return it != summary.end() && it->is_boolean() && it->get<bool>();
    };
    const auto count = [&](const char* key) {
      const auto it = summary.find(key);
      return it != summary.end() && it->is_number() ? it->get<long>() : 0L;
    };
    fmt::print("{}: strain {:.4g} in {} steps, {:.1f} s ({:.3g} ms/step); max overlap {:.3g} d\n",
               out_dir, num(summary, "strain"), count("steps"), num(summary, "wall_seconds"),
               num(summary, "ms_per_step"), num(summary, "max_overlap"));
    if (summary.contains("steady")) {
      if (!flag("steady")) {
        fmt::print("  steady state NOT reached (H or mu still drift); phi(now) = {:.4f}\n",
                   num(summary, "phi"));
      } else {
        fmt::print("  steady from strain {:.3g}: phi = {:.4f} +- {:.4f}, mu = {:.4f}, H = {:.3f} d\n",
                   num(summary, "steady_strain"), num(summary, "phi"), num(summary, "phi_std"),
                   num(summary, "mu"), num(summary, "H"));
        fmt::print("  wall pressure check: measured {:.12f} P (max relative error {:.2e} over {} "
                   "held steps)\n",
                   num(summary, "pressure_measured"), num(summary, "pressure_max_relative_error"),
                   count("steps") - count("wall_free_fall_steps"));
      }
    } else if (std::isnan(num(summary, "shear_stress"))) {
      fmt::print("  no averages: the run ended before run.transient_strain\n");
    } else {
      fmt::print("  shear stress {:.5g} P, particle pressure {:.5g} P, viscosity {:.4g} eta\n",
                 num(summary, "shear_stress"), num(summary, "pressure"), num(summary, "viscosity"));
    }
    if (summary.contains("D"))
      fmt::print("  diffusion: D = {:.4g} gammadot d^2 (MSD window [{:g}, {:g}]), dv = {:.4g} "
                 "gammadot d, Psi = {:.4g} / gammadot\n",
                 num(summary, "D"), num_at(summary, "msd_window", 0),
                 num_at(summary, "msd_window", 1), num(summary, "dv"), num(summary, "psi"));
    print_warnings(summary);
    return 0;
  } catch (const sheardiff::RunUnhealthy& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    fmt::print(stderr, "  diagnostic frame: {}/diagnostic.txt; checkpoint {}\n", out_dir,
               e.report.state_finite ? "written at this step" : "not written (state not finite; "
                                                                 "the previous one, if any, kept)");
    return sheardiff::kExitUnhealthy;
  } catch (const sheardiff::RunInterrupted& e) {
    fmt::print(stderr, "{}\n", e.what());
    return 128 + e.signal;
  } catch (const sheardiff::ConfigError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitConfig;
  } catch (const std::runtime_error& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitNumerical;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
}
