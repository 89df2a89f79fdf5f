#pragma once
// A batch of runs over the product of config axes (J, ktilde, N, seed, ...): the sweep file, its
// points, the local process pool, the Slurm job array, and the collection into sweep.csv and
// fits.json. Every point is an ordinary run directory DIR/points/<name>/ (docs/sweeps.md).
#include <filesystem>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "sheardiff/config.hpp"

namespace sheardiff {

class RunDirectory;

struct SweepSpec {
  std::filesystem::path file;  // the sweep file itself (absolute)
  std::filesystem::path base;  // base config (absolute; relative paths resolve from `file`)
  // Overrides applied to every point, then one value per axis: "section.key" -> values, the
  // values kept as TOML text so that they reach the config parser exactly as --set would.
  std::vector<std::pair<std::string, std::string>> set;
  std::vector<std::pair<std::string, std::vector<std::string>>> axes;
  // Keys whose value goes with an axis's entries, one value per entry, not an axis of their
  // own ([sweep.paired."flow.J"], e.g. each J started near its own steady phi): the axis index,
  // the key and its values. They do not enter the point names.
  struct Paired {
    std::size_t axis;
    std::string key;
    std::vector<std::string> values;
  };
  std::vector<Paired> paired;
  int jobs = 2;
  std::string backend = "local";
  // Optional: where finished points' small results persist (summary.json, config.toml,
  // analysis.h5 or channel.h5; no trajectories), e.g. results/<sweep name> in the repository.
  // Points found there count as finished, and --collect works from it alone (docs/sweeps.md).
  std::filesystem::path results;
  struct Slurm {
    int throttle = 0;  // at most this many array tasks at once; 0 = no limit
    std::string time = "1-00:00:00", partition, job_name = "sheardiff";
    int cpus_per_task = 1;
    std::string mem_per_task = "2G";
    std::vector<std::string> extra;  // further sbatch options, e.g. "--account=foo"
  } slurm;
};

struct SweepPoint {
  long index = 0;
  std::string name;                    // directory name, e.g. J=0.001_ktilde=10000_N=250_seed=1
  std::vector<std::string> overrides;  // "key=value", set then axes
  double cost = 1;                     // relative cost estimate, for scheduling and the ETA
};

// Reads and checks the sweep file, then builds and validates every point's config before any
// work starts (validate_run_inputs included); two equal values of an axis, or two points with
// one resolved config, are refused. Throws ConfigError naming the file and key.
SweepSpec load_sweep(const std::filesystem::path& file);
// Whether a TOML file is a sweep file (has a [sweep] table): `sheardiff check` takes both.
bool is_sweep_file(const std::filesystem::path& file);
std::vector<SweepPoint> expand_points(const SweepSpec& spec);

std::filesystem::path point_dir(const std::filesystem::path& out_dir, const SweepPoint& p);

enum class PointState { finished, resumable, fresh };
// finished: summary.json present and config.toml equal to the point's config; a point directory
// holding another config is an error (never mix). resumable: a checkpoint.bin is there.
PointState point_state(const SweepSpec& spec, const SweepPoint& p,
                       const std::filesystem::path& out_dir);

// A point another process is running (its lock is held): not a failure of the point.
struct PointBusy : ConfigError {
  using ConfigError::ConfigError;
};

// Runs one point to its end in this process (resuming, or starting afresh over the remains of
// a start killed before its first checkpoint, as its state says), in its run directory's lock;
// `report` (if given) is called with the summary while the run directory's log is open.
// Throws PointBusy if another process runs the point, else what run_to_directory throws.
void run_point(const SweepSpec& spec, const SweepPoint& p, const std::filesystem::path& out_dir,
               const std::function<void(const RunDirectory&, const nlohmann::json&)>& report = {});

// Local backend: `jobs` worker processes of `exe sweep FILE --out DIR --point I`, progress
// lines on stderr if `progress` (with an ISO 8601 UTC timestamp off a terminal), SIGINT/SIGTERM
// forwarded (workers checkpoint). Returns the number of failed points (the command then exits
// 3); throws RunInterrupted on a signal.
int run_local(const SweepSpec& spec, const std::filesystem::path& out_dir, int jobs,
              const std::filesystem::path& exe, bool progress = true);

// The local pool's oversubscription check (docs/performance.md, "Threads"): workers x threads
// per worker (OMP_THREAD_LIMIT) above the cores this process may use makes every point slower
// without raising the throughput. Returns the warning to print, or an empty string.
std::string oversubscription_warning(int jobs, int threads_per_job, int cores);

// Slurm backend: writes DIR/slurm/{array,collect}.sbatch and submits the array (unfinished
// points only, % throttle) and a collect job depending on it. Returns the two job ids.
std::pair<std::string, std::string> submit_slurm(const SweepSpec& spec,
                                                 const std::filesystem::path& out_dir,
                                                 const std::filesystem::path& exe);

// Copies a finished point's small results (summary.json, config.toml, analysis.h5 or
// channel.h5) into spec.results/points/<name>/ (each file atomically; nothing if spec.results
// is empty or the point is not finished in out_dir). Returns whether it copied.
bool export_point(const SweepSpec& spec, const SweepPoint& p, const std::filesystem::path& out_dir);
// The stored results of a point: spec.results/points/<name>/ if it holds a summary.json of
// this point's config, else an empty path.
std::filesystem::path stored_point(const SweepSpec& spec, const SweepPoint& p);

// Reads every point's summary.json (from DIR/points, or from the stored results when the run
// directory lacks it), exports finished points to spec.results, and writes DIR/sweep.csv and
// DIR/fits.json (atomically; also into spec.results). Returns fits.json.
nlohmann::json collect_sweep(const SweepSpec& spec, const std::filesystem::path& out_dir);

// The seed's laws fitted over the finished points of several stores or sweep folders, as one
// group (same N, ktilde, mixing, ...; refused otherwise): each J is taken from the first store
// that holds a point at it, so a re-measured store listed first replaces an older one's J.
// Points whose measured window failed the stationarity test are left out, and so are older
// points (written before that test) whose mu_top - mu_bottom exceeds steady.drift_z combined
// errors. Writes out_dir/sweep.csv (every point with its status and store), out_dir/fits.json
// and out_dir/fit_sources.txt; refuses a folder holding a sweep or a store. Returns fits.json.
// include_drifting: points flagged by the stationarity test enter the fits as well (a
// sensitivity check, recorded in fits.json as includes_not_stationary).
nlohmann::json fit_stores(const std::vector<std::filesystem::path>& stores,
                          const std::filesystem::path& out_dir, bool include_drifting = false);

// The fits of one group of runs (same ktilde, N, ...): power laws of D, dv, Psi against J and
// against phi_c - phi, phi(J) = phi_c - a J^b and mu(J) = mu_c + a J^b. rows: one per J, keys
// J, phi, mu, D, dv, psi (seeds already averaged). Fits that lack points hold {"error": why}.
nlohmann::json fit_group(const std::vector<nlohmann::json>& rows);

// Standard deviations of every fit parameter over `replicates` bootstrap draws of the seeds at
// each J (runs keyed by J; each run a summary with phi, mu, D, dv, psi), with the small-sample
// correction described in collect.cpp. Empty when every J has one run.
nlohmann::json seed_bootstrap(const std::map<double, std::vector<nlohmann::json>>& by_j,
                              long replicates);

}  // namespace sheardiff
