// Command line of sheardiff: run a config, validate one, or print the config reference.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <iostream>

#include "sheardiff/config.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/simulation.hpp"
#include <cmath>

namespace {
// Exit codes (docs/config.md): 0 done, 2 invalid config or input, 3 the run failed numerically,
// 1 anything else (I/O).
constexpr int kExitConfig = 2;
constexpr int kExitNumerical = 3;
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
                 run_dir, js["D"].get<double>(), js["D_stderr"].get<double>(),
                 js["msd_window"][0].get<double>(), js["msd_window"][1].get<double>(),
                 js["msd_window_slope"].is_null() ? NAN : js["msd_window_slope"].get<double>(),
                 js["dv"].get<double>(), js["psi"].get<double>(), js["step_length"].get<double>());
      for (const auto& w : js["analysis_warnings"]) fmt::print(stderr, "warning: {}\n", w.get<std::string>());
      return 0;
    }
    const sheardiff::Config cfg = sheardiff::load_config(config_path, overrides);
    if (check->parsed()) {
      std::cout << sheardiff::to_toml(cfg);
      return 0;
    }
    const bool resume = !resume_dir.empty();
    if (resume) out_dir = resume_dir;
    const auto summary = sheardiff::run_to_directory(cfg, out_dir, true, resume);
    fmt::print("{}: strain {:.4g} in {} steps, {:.1f} s ({:.3g} ms/step); max overlap {:.3g} d\n",
               out_dir, summary["strain"].get<double>(), summary["steps"].get<long>(),
               summary["wall_seconds"].get<double>(), summary["ms_per_step"].get<double>(),
               summary["max_overlap"].get<double>());
    if (summary.contains("steady")) {
      if (!summary["steady"].get<bool>()) {
        fmt::print("  steady state NOT reached (H or mu still drift); phi(now) = {:.4f}\n",
                   summary["phi"].get<double>());
      } else {
        fmt::print("  steady from strain {:.3g}: phi = {:.4f} +- {:.4f}, mu = {:.4f}, H = {:.3f} d\n",
                   summary["steady_strain"].get<double>(), summary["phi"].get<double>(),
                   summary["phi_std"].get<double>(), summary["mu"].get<double>(),
                   summary["H"].get<double>());
        fmt::print("  wall pressure check: measured {:.12f} P (max relative error {:.2e} over {} "
                   "held steps)\n",
                   summary["pressure_measured"].get<double>(),
                   summary["pressure_max_relative_error"].get<double>(),
                   summary["steps"].get<long>() - summary["wall_free_fall_steps"].get<long>());
      }
    } else if (summary["shear_stress"].is_null()) {
      fmt::print("  no averages: the run ended before run.transient_strain\n");
    } else {
      fmt::print("  shear stress {:.5g} P, particle pressure {:.5g} P, viscosity {:.4g} eta\n",
                 summary["shear_stress"].get<double>(), summary["pressure"].get<double>(),
                 summary["viscosity"].get<double>());
    }
    if (summary.contains("D"))
      fmt::print("  diffusion: D = {:.4g} gammadot d^2 (MSD window [{:g}, {:g}]), dv = {:.4g} "
                 "gammadot d, Psi = {:.4g} / gammadot\n",
                 summary["D"].get<double>(), summary["msd_window"][0].get<double>(),
                 summary["msd_window"][1].get<double>(), summary["dv"].get<double>(),
                 summary["psi"].get<double>());
    if (summary.contains("analysis_warnings"))
      for (const auto& w : summary["analysis_warnings"])
        fmt::print(stderr, "warning: {}\n", w.get<std::string>());
    return 0;
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
