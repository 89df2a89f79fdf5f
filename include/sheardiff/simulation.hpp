#pragma once
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/core/output_schedule.hpp"
#include "sheardiff/integrator/integrators.hpp"
#include "sheardiff/observe/stress.hpp"
#include "sheardiff/scene/scene.hpp"

namespace sheardiff {

// A run as a value: the scene, the engine composed for it and the integrator. Tests build one
// from a Config (or a hand-made Scene) and step it.
class Simulation {
 public:
  explicit Simulation(const Config& cfg);
  Simulation(const Config& cfg, Scene scene);

  // One integrator step; throws std::runtime_error if the linear solve fails.
  void step();
  // One integrator step; false if the linear solve failed (the state is then unchanged).
  bool try_step() { return integrator_->step(*dynamics_); }
  StressSample sample() const { return integrator_->sample(*dynamics_, cfg_.flow.lz); }

  const Config& config() const { return cfg_; }
  Dynamics& dynamics() { return *dynamics_; }
  const Dynamics& dynamics() const { return *dynamics_; }
  const Integrator& integrator() const { return *integrator_; }
  void serialize_integrator(Archive& a) { integrator_->serialize(a); }

 private:
  Config cfg_;
  std::unique_ptr<Integrator> integrator_;
  std::unique_ptr<Dynamics> dynamics_;
};

// Pair interaction range over the sum of the radii: lubrication reaches gaps up to h_max.
double interaction_range_factor(const Config& cfg);

// Contact stability limit of explicit springs for these parameters (docs/model.md section 7).
double explicit_stability_dt(const Config& cfg);

class Observer;
// The observers the scene and the config ask for (and only those), in their update order.
std::vector<std::unique_ptr<Observer>> make_observers(const Config& cfg,
                                                      const std::filesystem::path& out_dir);

// Whether the run needs the rotational unknowns (3 per particle) or only translation (2).
bool rotational_unknowns(const Config& cfg);

// The checks of a configuration that need the physics or input files (parse_config does the
// rest): a fixed dt of explicit springs below their stability limit, particles.init_file
// readable with particles.N mobile particles, and a periodic cell wider than two neighbour
// cut-offs of the largest pair. Throws ConfigError naming origin and the key.
// Writes nothing: `sheardiff check` and `run` call it before any output exists.
void validate_run_inputs(const Config& cfg, const std::string& origin);

// A run stopped by SIGINT/SIGTERM after writing its checkpoint.
struct RunInterrupted : std::runtime_error {
  RunInterrupted(int sig, const std::string& what) : std::runtime_error(what), signal(sig) {}
  int signal;
};


class RunDirectory;
// How run_to_directory treats what DIR already holds (docs/stability.md, "Run directories"):
//   start      DIR must hold no run;
//   overwrite  the run files of any earlier run are removed first;
//   resume     continue DIR's run: from its checkpoint; from strain 0 if it stopped before
//              its first one (refused when DIR holds more than such a start leaves:
//              restart_would_lose); a finished run is left as it is (its checkpoint, if a death
//              left one behind, removed) and its summary returned.
enum class RunMode { start, overwrite, resume };

// Runs cfg to its end in the locked directory `dir`, writing trajectory.h5 (H5MD), config.toml,
// checkpoint.bin every output.checkpoint_strain, run.log, and at the end summary.json (whose
// presence marks a finished run; the checkpoint is then removed). A resumed run cuts the
// trajectory back to the checkpoint's frames and continues bit-identically to a run never
// stopped. Nothing in DIR is changed before the configuration, the initial state and the
// checkpoint have been checked. Throws ConfigError (exit 2: refused, nothing changed), IoError
// (exit 1: DIR left resumable), RunUnhealthy (4), RunInterrupted (128 + signal). Returns the
// summary (with the version, git hash, host, seed, start and end time of the run).
// progress: progress on stderr, a live line on a terminal, else a line with an ISO 8601 UTC
// timestamp every progress_seconds; run.log gets those timestamped lines in any case.
nlohmann::json run_to_directory(const Config& cfg, RunDirectory& dir, RunMode mode, bool progress,
                                double progress_seconds = 60.0);
// What a restart from strain 0 would delete in DIR when it holds neither checkpoint.bin nor
// summary.json: an analysis written at a run's end, or frames past the first checkpoint's
// strain (the checkpoint or the summary of a run that got further was removed). Returns the
// refusal to print, naming what is there and what the user can do, or "" when DIR holds only
// the remains of a start killed before its first checkpoint (or a finished/interrupted run).
std::string restart_would_lose(const RunDirectory& dir, const Config& cfg);

// The same in a RunDirectory of its own: resume ? RunMode::resume : RunMode::start.
nlohmann::json run_to_directory(const Config& cfg, const std::filesystem::path& out_dir,
                                bool progress, bool resume = false);

}  // namespace sheardiff
