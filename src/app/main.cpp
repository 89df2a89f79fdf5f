// Command line of sheardiff: run a config, validate one, analyse a run, run a sweep, or print
// the config reference. What a finished run or analysis prints is in result_text.cpp.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <system_error>

#include "result_text.hpp"
#include "sheardiff/config.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/hdf5_diagnostics.hpp"
#include "sheardiff/io/io_error.hpp"
#include "sheardiff/io/run_directory.hpp"
#include "sheardiff/io/summary_keys.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/observe/run_health.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/solver/blas_kernels.hpp"
#include "sheardiff/sweep/sweep.hpp"
#include "sheardiff/version.hpp"

namespace {
// Exit codes (README, docs/stability.md): 0 done, 1 I/O and other errors, 2 refused before
// anything was changed (invalid configuration, input file or command line; a run directory in
// use or holding a run the command may not touch; a corrupt checkpoint), 3 a numerical failure
// outside the step loop, or a sweep with points that failed or did not finish, 4 stopped by a
// run health check (kExitUnhealthy), 128 + signal after SIGINT/SIGTERM.
constexpr int kExitIo = 1;
constexpr int kExitConfig = 2;
constexpr int kExitNumerical = 3;
// `sweep FILE --point I`: one point in this process (a worker of the pool or a Slurm task).
int sweep_point(const sheardiff::SweepSpec& spec, const std::filesystem::path& out, long point) {
  namespace sd = sheardiff;
  const auto points = sd::expand_points(spec);
  if (point >= static_cast<long>(points.size()))
    throw sd::ConfigError(
        fmt::format("--point {}: the sweep has points 0 to {}", point, points.size() - 1));
  const auto& p = points[point];
  // A failure is recorded next to the log, so that sweep.csv can say which point failed how.
  const auto marker = out / "logs" / (p.name + ".failed");
  std::filesystem::create_directories(out / "logs");
  std::filesystem::remove(marker);
  try {
    // The point's result, as `run` prints it: into the pool's logs/<point>.log (this worker's
    // output) and the point's run.log.
    sd::run_point(spec, p, out, [&](const sd::RunDirectory&, const nlohmann::json& summary) {
      const std::string dir = sd::point_dir(out, p).string();
      fmt::print("{}{}", sd::run_result_first_line(summary, dir), sd::run_result_details(summary));
      sd::print_warnings(summary);
      std::fflush(stdout);
    });
    return 0;
  } catch (const sd::PointBusy&) {
    throw;  // not a failure of the point: no marker
  } catch (const sd::RunInterrupted&) {
    throw;
  } catch (const std::exception& e) {
    sd::write_file_atomically(marker, fmt::format("{}\n", e.what()));
    throw;
  }
}

int run_sweep(const std::string& file, const std::filesystem::path& out, int jobs,
              std::string backend, long point, bool collect_only, bool quiet) {
  namespace sd = sheardiff;
  const auto spec = sd::load_sweep(file);
  if (backend.empty()) backend = spec.backend;
  if (point >= 0) return sweep_point(spec, out, point);
  int failed = 0;
  if (!collect_only) {
    const auto exe = std::filesystem::read_symlink("/proc/self/exe");
    if (backend == "slurm") {
      const auto [array, collect] = sd::submit_slurm(spec, out, exe);
      fmt::print(
          "submitted: job array {} (unfinished points), collect job {} after it; results "
          "in {}/sweep.csv and fits.json\n",
          array.empty() ? "none" : array, collect, out.string());
      return 0;
    }
    failed = sd::run_local(spec, out, jobs > 0 ? jobs : spec.jobs, exe, !quiet);
    if (failed > 0)
      fmt::print(stderr, "sweep: {} point(s) failed; collecting the others\n", failed);
  }
  const auto fits = sd::collect_sweep(spec, out);
  fmt::print("{}: {}/{} points finished; {}/sweep.csv, {}/fits.json\n", out.string(),
             fits["finished"].get<long>(), fits["points"].get<long>(), out.string(), out.string());
  // --quiet: the one line above; the fits are in fits.json.
  const nlohmann::json none = nlohmann::json::array();
  for (const auto& g : quiet ? none : fits["groups"]) {
    const auto& f = g["fits"];
    fmt::print("  {}:", g["axes"].dump());
    for (const char* k : {"D_vs_J", "dv_vs_J", "psi_vs_J"})
      if (f[k].contains("b")) {
        // The quoted error is the seeds' scatter: none with one seed per J.
        const auto& e = f[k]["b_stderr"];
        fmt::print(" {} = {:.3g} J^{:.3f}{};", k, f[k]["a"].get<double>(), f[k]["b"].get<double>(),
                   e.is_number() ? fmt::format("+-{:.3f}", e.get<double>()) : "");
      }
    if (f["phi_of_J"].contains("phi_c"))
      fmt::print(" phi = {:.4f} - {:.3g} J^{:.3f}", f["phi_of_J"]["phi_c"].get<double>(),
                 f["phi_of_J"]["a"].get<double>(), f["phi_of_J"]["b"].get<double>());
    fmt::print("\n");
  }
  if (failed > 0 || fits["finished"].get<long>() != fits["points"].get<long>()) {
    fmt::print(
        stderr, "sweep: {} of {} points not finished{}\n",
        fits["points"].get<long>() - fits["finished"].get<long>(), fits["points"].get<long>(),
        failed > 0 ? fmt::format(" ({} failed in this sweep; see {}/logs)", failed, out.string())
                   : "");
    return kExitNumerical;
  }
  return 0;
}

// --out of every subcommand: a folder of its own, never "" or a filesystem root ("/" as root
// would spread a run's files over the system).
const CLI::Validator kOutFolder(
    [](std::string& s) -> std::string {
      if (s.empty()) return "an empty path; give the output folder";
      std::error_code ec;
      const auto p = std::filesystem::weakly_canonical(std::filesystem::absolute(s, ec), ec);
      if (!ec && p == p.root_path())
        return fmt::format("{} is a filesystem root; give a folder of its own", s);
      return {};
    },
    "FOLDER");

// Seconds: a finite number above 0 (CLI::PositiveNumber lets "nan" and "inf" through).
const CLI::Validator kPositiveFinite(
    [](std::string& s) -> std::string {
      double v = 0.0;
      try {
        std::size_t used = 0;
        v = std::stod(s, &used);
        if (used != s.size()) return fmt::format("{}: not a number", s);
      } catch (const std::exception&) {
        return fmt::format("{}: not a number", s);
      }
      return std::isfinite(v) && v > 0.0 ? std::string()
                                         : fmt::format("{}: must be a finite number > 0", s);
    },
    "SECONDS > 0");

// Every subcommand and option of the command line.
struct CommandLine {
  CommandLine();
  void add_run();
  void add_check_and_doc();
  void add_analyse();
  void add_sweep();
  void add_fit();
  CLI::App app{"sheardiff: overdamped frictional DEM of dense non-Brownian suspensions"};
  CLI::App *run, *check, *doc, *keys_doc, *analyse, *sweep, *fit;
  std::string config_path, out_dir = "out", resume_dir, run_dir, sweep_file, backend;
  std::vector<std::string> overrides, stores;
  bool overwrite = false, quiet = false, markdown = false, collect_only = false,
       include_drifting = false;
  double progress_seconds = 60.0;
  int jobs = 0;
  long point = -1;
};

CommandLine::CommandLine() {
  app.require_subcommand(1);
  app.set_version_flag("--version", sheardiff::version_line(),
                       "Print the version and git commit, and exit");
  add_run();
  add_check_and_doc();
  add_analyse();
  add_sweep();
  add_fit();
}

void CommandLine::add_run() {
  run = app.add_subcommand("run", "Run a configuration to its end");
  run->add_option("config", config_path, "Configuration file (TOML, see docs/config.md)")
      ->required();
  auto* out_opt =
      run->add_option("--out", out_dir,
                      "Output folder: trajectory.h5 (H5MD), summary.json, config.toml, "
                      "run.log. A folder holding a run is refused (see --resume, --overwrite)")
          ->capture_default_str()
          ->check(kOutFolder);
  run->add_option("--set", overrides,
                  "Override one key, section.key=value (repeatable), e.g. --set flow.J=1e-3");
  auto* resume_opt = run->add_option(
      "--resume", resume_dir,
      "Continue the run in DIR from its checkpoint.bin (same CONFIG and --set); the "
      "trajectory is cut back to the checkpoint, the result is bit-identical to an "
      "uninterrupted run. A run stopped before its first checkpoint starts again; a finished "
      "one is left as it is");
  auto* overwrite_opt = run->add_flag(
      "--overwrite", overwrite,
      "Run in --out DIR even if it holds a run: every file of that run is deleted first");
  resume_opt->excludes(out_opt);
  resume_opt->excludes(overwrite_opt);
  run->add_flag("-q,--quiet", quiet,
                "No progress line; errors, warnings and the result's first line are still "
                "printed, and DIR/run.log still gets everything");
  run->add_option("--progress-every", progress_seconds,
                  "Seconds between the timestamped progress lines written off a terminal and "
                  "to DIR/run.log")
      ->capture_default_str()
      ->check(kPositiveFinite);
}

void CommandLine::add_check_and_doc() {
  check = app.add_subcommand("check", "Validate a configuration and print it resolved");
  check->add_option("config", config_path, "Configuration file (TOML)")->required();
  check->add_option("--set", overrides, "Override one key, section.key=value (repeatable)");

  doc = app.add_subcommand(
      "config-doc",
      "Print every config key with its meaning, type, range, unit and default, as a commented "
      "TOML file of the defaults (lines of at most 100 columns)");
  doc->add_flag("--markdown", markdown,
                "Print the Markdown table instead (the one docs/config.md is made from)");

  keys_doc = app.add_subcommand(
      "summary-keys",
      "Print every key a run may write to summary.json with its unit and meaning, as a JSON "
      "list (what tools/rundir.py checks names against)");
  keys_doc->add_flag("--markdown", markdown,
                     "Print the Markdown tables instead (the ones docs/outputs.md holds)");
}

void CommandLine::add_analyse() {
  analyse = app.add_subcommand(
      "analyse",
      "Recompute the analysis (MSD, D, dv, VACF, Psi; the pressure cell's error bars and "
      "stationarity) of a finished run from DIR/trajectory.h5 alone. Adds what the run lacked to "
      "DIR/summary.json and never changes a number it wrote: a result that differs, or one with "
      "--set, goes to DIR/reanalysis/");
  analyse->add_option("dir", run_dir, "Run directory")->required();
  analyse->add_option("--set", overrides,
                      "Analyse the same frames with another setting, analysis.KEY=value or "
                      "observables.KEY=value (repeatable), e.g. --set analysis.msd_window_lo=4");
}

void CommandLine::add_sweep() {
  sweep = app.add_subcommand(
      "sweep",
      "Run every point of a sweep file (axes over J, ktilde, N, seeds, ...) as its own "
      "run directory DIR/points/NAME, skipping finished points and resuming "
      "interrupted ones, then write DIR/sweep.csv and DIR/fits.json (docs/sweeps.md)");
  sweep->add_option("sweep_file", sweep_file, "Sweep file (TOML)")->required();
  sweep->add_option("--out", out_dir, "Sweep folder")->required()->check(kOutFolder);
  sweep->add_option("--jobs", jobs, "Worker processes (local backend; default sweep.jobs)")
      ->check(CLI::Range(1, 256));
  sweep->add_option("--backend", backend, "local or slurm (default sweep.backend)")
      ->check(CLI::IsMember({"local", "slurm"}));
  sweep->add_option("--point", point, "Run only point I (what a worker or a Slurm task does)")
      ->check(CLI::NonNegativeNumber);
  sweep->add_flag("--collect", collect_only,
                  "Only collect finished points into sweep.csv and "
                  "fits.json (what the Slurm collect job does)");
  sweep->add_flag("-q,--quiet", quiet,
                  "No progress lines; failures and the result's first line are still printed");
}

void CommandLine::add_fit() {
  fit = app.add_subcommand(
      "fit",
      "Fit the seed's laws over the finished points of several stores or sweep folders as one "
      "group: each J from the first listed that holds it, points that failed the stationarity "
      "test left out; writes OUT/sweep.csv, OUT/fits.json (docs/sweeps.md)");
  fit->add_option("stores", stores, "Stores (results/NAME) or sweep folders, in priority order")
      ->required();
  fit->add_option("--out", out_dir, "Folder for sweep.csv and fits.json (not a sweep's own)")
      ->required()
      ->check(kOutFolder);
  fit->add_flag("--include-not-stationary", include_drifting,
                "Fit the points flagged by the stationarity test too (a sensitivity check; "
                "fits.json says so)");
}

// `sheardiff analyse DIR`: the diffusion analysis of a finished run, again.
int analyse_command(const CommandLine& cl, std::optional<sheardiff::RunDirectory>& dir) {
  const std::string& run_dir = cl.run_dir;
  dir.emplace(run_dir, false);
  if (dir->state() != sheardiff::RunState::finished)
    throw sheardiff::ConfigError(fmt::format(
        "{}: analyse needs a finished run (summary.json); this directory holds {}", run_dir,
        dir->state() == sheardiff::RunState::empty ? "no run" : "a run that has not finished"));
  const auto run_cfg =
      sheardiff::load_config(dir->file("config.toml"), {}, sheardiff::ConfigSource::record);
  {
    // Read here so that a damaged summary is named (reanalyse_run would not name it).
    std::ifstream in(dir->file("summary.json"));
    try {
      const auto summary = nlohmann::json::parse(in);
      (void)summary;
    } catch (const nlohmann::json::exception& e) {
      throw sheardiff::ConfigError(
          fmt::format("{}: not a valid summary: {}", dir->file("summary.json").string(), e.what()));
    }
  }
  if (!run_cfg.output.trajectory)
    throw sheardiff::ConfigError(fmt::format(
        "{}: the run was made with output.trajectory = false: there is no trajectory to "
        "analyse",
        run_dir));
  dir->start_log(sheardiff::this_command_line());
  dir->remove_partial_files();  // of an earlier analyse killed while writing
  sheardiff::Reanalysis re;
  dir->with_hdf5_reasons([&] { re = sheardiff::reanalyse_run(run_dir, cl.overrides); });
  const nlohmann::json& js = re.summary;
  fmt::print("{}", sheardiff::analysis_result_text(js, run_dir));
  if (!cl.overrides.empty())
    fmt::print("the analysis with {}{}: written to {}; the run's files are as they were\n",
               fmt::join(cl.overrides, ", "),
               re.differs.empty() ? std::string()
                                  : fmt::format(" (changes {})", fmt::join(re.differs, ", ")),
               re.folder.string());
  else if (!re.differs.empty())
    fmt::print(
        "the analysis differs from the run's own in {}: written to {} (summary.json, "
        "analysis.h5); the run's files are as they were\n",
        fmt::join(re.differs, ", "), re.folder.string());
  sheardiff::print_warnings(js);
  return 0;
}

// `sheardiff check SWEEP.toml`: every point's config is built and validated, then listed.
int check_sweep_command(const CommandLine& cl) {
  if (!cl.overrides.empty())
    throw sheardiff::ConfigError("--set applies to run configs; a sweep sets keys in [sweep.set]");
  const auto spec = sheardiff::load_sweep(cl.config_path);
  const auto points = sheardiff::expand_points(spec);
  fmt::print("{}: a sweep of {} points over {}, every point's config valid:\n", cl.config_path,
             points.size(), spec.base.string());
  for (const auto& p : points) fmt::print("  {}\n", p.name);
  return 0;
}

// A run goes into a new folder, an empty one or a run's: a folder holding other files and no
// run file (a home directory, a project folder) is refused before anything is written there.
void refuse_foreign_folder(const std::filesystem::path& out) {
  std::error_code ec;
  if (!std::filesystem::is_directory(out, ec)) return;
  std::vector<std::string> run_names;
  for (const auto& n : sheardiff::run_file_names()) {
    run_names.push_back(n);
    run_names.push_back(n + ".tmp");
  }
  std::vector<std::string> others;
  bool run_file = false;
  for (const auto& e : std::filesystem::directory_iterator(out, ec)) {
    const std::string name = e.path().filename().string();
    if (std::find(run_names.begin(), run_names.end(), name) != run_names.end())
      run_file = true;
    else
      others.push_back(name);
  }
  if (run_file || others.empty()) return;
  std::sort(others.begin(), others.end());
  if (others.size() > 3) others.resize(3), others.push_back("...");
  throw sheardiff::ConfigError(fmt::format(
      "--out {}: the folder holds other files ({}) and no run; a run goes into a new or empty "
      "folder (nothing was written)",
      out.string(), fmt::join(others, ", ")));
}

// `sheardiff check CONFIG` and `sheardiff run CONFIG`.
int config_command(CommandLine& cl, std::optional<sheardiff::RunDirectory>& dir) {
  const bool resume = !cl.check->parsed() && !cl.resume_dir.empty();
  // `run DIR/config.toml --resume DIR` gives the run's own record: it reads as the run it was.
  std::error_code record_ec;
  const bool own_record =
      resume &&
      std::filesystem::equivalent(cl.config_path,
                                  std::filesystem::path(cl.resume_dir) / "config.toml", record_ec);
  const sheardiff::Config cfg = sheardiff::load_config(
      cl.config_path, cl.overrides,
      own_record ? sheardiff::ConfigSource::record : sheardiff::ConfigSource::file);
  sheardiff::validate_run_inputs(cfg, cl.config_path);
  if (cl.check->parsed()) {
    std::cout << sheardiff::to_toml(cfg);
    return 0;
  }
  if (resume) cl.out_dir = cl.resume_dir;
  using sheardiff::RunMode;
  const RunMode mode = resume         ? RunMode::resume
                       : cl.overwrite ? RunMode::overwrite
                                      : RunMode::start;
  // --overwrite deletes DIR/config.toml: it must not be the file the user runs.
  std::error_code same_ec;
  if (mode == RunMode::overwrite &&
      std::filesystem::equivalent(cl.config_path, std::filesystem::path(cl.out_dir) / "config.toml",
                                  same_ec))
    throw sheardiff::ConfigError(fmt::format(
        "{} is the config.toml of the run in {}, which --overwrite deletes: copy it elsewhere "
        "and run that copy",
        cl.config_path, cl.out_dir));
  if (mode != RunMode::resume) refuse_foreign_folder(cl.out_dir);
  dir.emplace(cl.out_dir, mode != RunMode::resume);
  const auto summary = sheardiff::run_to_directory(cfg, *dir, mode, !cl.quiet, cl.progress_seconds);
  fmt::print("{}", sheardiff::run_result_first_line(summary, cl.out_dir));
  // The lines after the first: on the terminal unless --quiet, in run.log always.
  const std::string details = sheardiff::run_result_details(summary);
  if (cl.quiet)
    dir->log_only(details);
  else
    fmt::print("{}", details);
  sheardiff::print_warnings(summary);
  return 0;
}

// The exit code of the exception being handled, its message printed.
int exit_code_of_failure(const std::string& out_dir) {
  try {
    throw;
  } catch (const sheardiff::RunUnhealthy& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    fmt::print(stderr, "  diagnostic frame: {}/diagnostic.txt; checkpoint {}\n", out_dir,
               e.report.state_finite ? "written at this step"
                                     : "not written (state not finite; "
                                       "the previous one, if any, kept)");
    return sheardiff::kExitUnhealthy;
  } catch (const sheardiff::RunInterrupted& e) {
    fmt::print(stderr, "{}\n", e.what());
    return 128 + e.signal;
  } catch (const sheardiff::ConfigError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitConfig;
  } catch (const sheardiff::IoError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitIo;
  } catch (const std::system_error& e) {  // std::filesystem errors: they name the path
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitIo;
  } catch (const std::runtime_error& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitNumerical;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitIo;
  }
}
}  // namespace

int main(int argc, char** argv) {
  // One solver thread and OpenBLAS kernels that use the CPU's vectors, unless the caller says
  // otherwise (docs/performance.md "Threads", "The BLAS kernels"): may re-execute once.
  sheardiff::set_solver_environment(argv);
  sheardiff::quiet_hdf5_for_process();
  CommandLine cl;
  try {
    cl.app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help is a ParseError with exit code 0; every usage error is exit 2.
    return cl.app.exit(e) == 0 ? 0 : kExitConfig;
  }
  // The run directory, locked, lives until main returns: what is printed, error messages
  // included, goes to its run.log too.
  std::optional<sheardiff::RunDirectory> dir;
  try {
    if (cl.doc->parsed()) {
      std::cout << (cl.markdown ? sheardiff::config_reference_markdown()
                                : sheardiff::config_reference_text());
      return 0;
    }
    if (cl.keys_doc->parsed()) {
      std::cout << (cl.markdown ? sheardiff::summary_keys_markdown()
                                : sheardiff::summary_keys_json().dump(1) + "\n");
      return 0;
    }
    if (cl.analyse->parsed()) return analyse_command(cl, dir);
    if (cl.sweep->parsed())
      return run_sweep(cl.sweep_file, cl.out_dir, cl.jobs, cl.backend, cl.point, cl.collect_only,
                       cl.quiet);
    if (cl.fit->parsed()) {
      std::vector<std::filesystem::path> stores(cl.stores.begin(), cl.stores.end());
      const auto fits = sheardiff::fit_stores(stores, cl.out_dir, cl.include_drifting);
      fmt::print("fit: {} points used, J fits in {}/fits.json, every point in {}/sweep.csv\n",
                 fits["finished"].get<long>(), cl.out_dir, cl.out_dir);
      return 0;
    }
    if (cl.check->parsed() && sheardiff::is_sweep_file(cl.config_path))
      return check_sweep_command(cl);
    return config_command(cl, dir);
  } catch (...) {
    return exit_code_of_failure(cl.out_dir);
  }
}
