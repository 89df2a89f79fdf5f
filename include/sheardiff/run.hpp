#pragma once
// A run in a directory: the directory rules (start, overwrite, resume), the step loop, the
// checkpoints and the summary. The engine it steps is engine.hpp; the parts it holds,
// run_parts.hpp.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/core/output_schedule.hpp"
#include "sheardiff/engine.hpp"

namespace sheardiff {

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
//              left one behind, removed) and its summary returned. Given a configuration
//              whose only changes move the run's end further (only_moves_the_end), the run is
//              extended: an interrupted one from its checkpoint, a finished one from its
//              final_state.bin after its results are set aside in earlier/
//              (set_aside_finished_results); steps, time and the analysis go on.
enum class RunMode { start, overwrite, resume };

// Runs cfg to its end in the locked directory `dir`, writing trajectory.h5 (H5MD), config.toml,
// checkpoint.bin every output.checkpoint_strain, run.log, and at the end summary.json (whose
// presence marks a finished run; the checkpoint is then removed and the end state kept as
// final_state.bin). A resumed run cuts the
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
