#include "sheardiff/run.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>

#include "sheardiff/core/text.hpp"
#include "sheardiff/integrator/stress.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/checkpoint_file.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/io/hdf5_diagnostics.hpp"
#include "sheardiff/io/io_error.hpp"
#include "sheardiff/io/run_directory.hpp"
#include "sheardiff/io/run_files.hpp"
#include "sheardiff/observe/observer.hpp"
#include "sheardiff/observe/run_health.hpp"
#include "sheardiff/run_extension.hpp"
#include "sheardiff/run_parts.hpp"
#include "sheardiff/version.hpp"

namespace sheardiff {

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

// How DIR/config.toml differs from this resolved configuration, key by key (compared through
// the parser, so that keys added to the code since do not make it look foreign); empty when it
// is the same.
std::vector<ConfigChange> changes_from(const std::filesystem::path& file,
                                       const std::string& resolved) {
  std::string was;
  try {
    was = to_toml(load_config(file, {}, ConfigSource::record));
  } catch (const ConfigError& e) {
    return {{file.string(), "a configuration", fmt::format("unreadable ({})", e.what())}};
  }
  auto changes = config_changes(was, resolved);
  if (changes.empty() && was != resolved) changes.push_back({"(form)", "one text", "another"});
  return changes;
}

// The changes for a message: those the user made, then, named apart, the keys that follow from
// them (a key whose new value the others give when it is left to resolve_defaults, e.g.
// output.frame_strain after a change of flow.J).
std::string listed(const std::vector<ConfigChange>& changes, const std::filesystem::path& file) {
  std::vector<std::string> made, follow;
  for (const auto& c : changes) {
    std::vector<std::string> others{c.key + "=0"};
    for (const auto& o : changes)
      if (o.key != c.key && !o.now.empty()) others.push_back(o.key + "=" + o.now);
    // Only a key that resolve_defaults fills in (0 = derived) can follow from the others.
    bool derived = false;
    try {
      const auto again =
          config_changes(to_toml(load_config(file, others, ConfigSource::record)), "");
      derived = !c.now.empty() && std::strtod(c.now.c_str(), nullptr) != 0.0 &&
                std::any_of(again.begin(), again.end(), [&](const ConfigChange& a) {
                  return a.key == c.key && a.was == c.now;
                });
    } catch (const ConfigError&) {
    }
    (derived ? follow : made).push_back(derived ? c.key : describe(c));
  }
  if (made.empty() || follow.empty()) {
    made.clear();
    for (const auto& c : changes) made.push_back(describe(c));
    return fmt::format("{}", fmt::join(made, "; "));
  }
  return fmt::format("{}; and, following from them, {}", fmt::join(made, "; "),
                     fmt::join(follow, ", "));
}

std::string refusal(const RunDirectory& dir) {
  const std::string d = dir.path().string();
  switch (dir.state()) {
    case RunState::finished:
      return fmt::format(
          "{} holds a finished run (summary.json); it is left as it is. To run there again add "
          "--overwrite (this deletes its results), or choose another --out",
          d);
    case RunState::interrupted:
      return fmt::format(
          "{} holds an interrupted run (checkpoint.bin); it is left as it is. Continue it with "
          "`sheardiff run CONFIG --resume {}`, or add --overwrite to discard it",
          d, d);
    case RunState::started:
      return fmt::format(
          "{} holds a run that stopped before its first checkpoint ({}); it is left as it is. "
          "`sheardiff run CONFIG --resume {}` starts it again from strain 0, --overwrite "
          "replaces it",
          d, dir.run_files_present(), d);
    case RunState::empty:
      break;
  }
  return {};
}

}  // namespace

nlohmann::json run_to_directory(const Config& cfg, const std::filesystem::path& out_dir,
                                bool progress, bool resume) {
  RunDirectory dir(out_dir, !resume);
  return run_to_directory(cfg, dir, resume ? RunMode::resume : RunMode::start, progress);
}

std::string restart_would_lose(const RunDirectory& dir, const Config& cfg) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir.file("summary.json"), ec) || fs::exists(dir.file("checkpoint.bin"), ec))
    return {};
  std::vector<std::string> kept;
  for (const char* name : kAnalyserFiles)
    if (fs::exists(dir.file(name), ec))
      kept.push_back(fmt::format("{} (written when a run finishes)", name));
  if (fs::exists(dir.file(kReanalysisFolder), ec))
    kept.push_back("reanalysis/ (written by analyse on a finished run)");
  if (fs::exists(dir.file(kFinalStateFile), ec))
    kept.push_back(fmt::format("{} (a finished run's end)", kFinalStateFile));
  if (fs::exists(dir.file(kEarlierFolder), ec))
    kept.push_back("earlier/ (a finished run's results, kept when it was extended)");
  const auto traj = dir.file("trajectory.h5");
  if (cfg.output.checkpoint_strain > 0 && fs::exists(traj, ec)) {
    // A start killed before its first checkpoint has frames up to about that strain (one more
    // frame may have reached the disk before the checkpoint did). A file too damaged to read is
    // such a start's (an unclosed file): it holds nothing to keep.
    try {
      if (has_h5md_observable(traj, "strain")) {
        const auto strain = read_h5md_observable(traj, "strain").value;
        const std::size_t n = strain.size();
        const double spacing = n >= 2 ? strain[n - 1] - strain[n - 2] : 0.0;
        if (n > 0 && strain.back() > cfg.output.checkpoint_strain + 1.5 * spacing + 1e-9)
          kept.push_back(
              fmt::format("trajectory.h5 ({} frames up to strain {:.4g}, past the "
                          "first checkpoint's {:.4g})",
                          n, strain.back(), cfg.output.checkpoint_strain));
      }
    } catch (const std::exception&) {
    }
  }
  if (kept.empty()) return {};
  return fmt::format(
      "{} holds {} but neither checkpoint.bin nor summary.json: the run got past its first "
      "checkpoint, and those files were removed or moved since. Nothing was changed. Without "
      "its checkpoint it cannot be continued, and starting again from strain 0 would delete "
      "what is there: put checkpoint.bin (or summary.json) back, or copy what you need and "
      "start again with --overwrite",
      dir.path().string(), fmt::join(kept, " and "));
}

namespace {

// Where a run given DIR starts from.
enum class Origin {
  fresh,        // strain 0
  checkpoint,   // DIR's checkpoint.bin (an interrupted run)
  final_state,  // DIR's final_state.bin: a finished run extended to a further end
  finished,     // nowhere: the run has finished and the configuration is the same
};

// What DIR holds decides what may be done (docs/stability.md, "Run directories"); nothing is
// changed here. Throws ConfigError for a refused command; `extending` is set when the run goes
// on to a further end (only_moves_the_end).
Origin check_directory(RunDirectory& dir, RunMode mode, const Config& cfg,
                       const std::string& resolved, bool& extending) {
  const std::string out = dir.path().string();
  const RunState state = dir.state();
  extending = false;
  if (mode == RunMode::start && state != RunState::empty) throw ConfigError(refusal(dir));
  if (mode != RunMode::resume) return Origin::fresh;
  if (state == RunState::empty)
    throw ConfigError(fmt::format("--resume {}: there is no run there to resume", out));
  if (state == RunState::started)
    if (const auto lost = restart_would_lose(dir, cfg); !lost.empty())
      throw ConfigError("--resume " + lost);
  if (std::filesystem::exists(dir.file(kConfigFile))) {
    const auto changes = changes_from(dir.file(kConfigFile), resolved);
    extending = only_moves_the_end(changes) && state != RunState::started;
    if (!changes.empty() && !extending)
      throw ConfigError(fmt::format(
          "--resume {}: the configuration differs from the one the run was started with ({}; "
          "see {}/config.toml). Only a further end may be given to a run: a larger run.strain "
          "or steady.measure_strain, a larger run.max_steps or 0{}",
          out, listed(changes, dir.file(kConfigFile)), out, changed_default_hint(changes)));
  }
  if (state == RunState::interrupted) return Origin::checkpoint;
  if (state != RunState::finished) return Origin::fresh;
  if (!extending) return Origin::finished;
  if (!std::filesystem::exists(dir.file(kFinalStateFile)))
    throw ConfigError(fmt::format(
        "--resume {}: the run finished without keeping its final state ({}; an earlier "
        "sheardiff removed it), so it cannot be extended; nothing was changed. Run the longer "
        "run into another directory",
        out, kFinalStateFile));
  return Origin::final_state;
}

// --resume of a finished run with the same configuration: a run killed between its summary and
// the removal of its checkpoint is finished; say so, complete the removal and return its summary.
nlohmann::json finished_run_summary(RunDirectory& dir) {
  dir.start_log("resume of a finished run: " + this_command_line());
  std::error_code ec;
  std::filesystem::remove(dir.file("checkpoint.bin"), ec);
  std::fprintf(stderr, "%s: the run has already finished (summary.json); nothing to resume\n",
               dir.path().c_str());
  std::ifstream in(dir.file("summary.json"));
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(fmt::format("cannot read {}: {}", dir.file("summary.json").string(), e.what()));
  }
}

// The directory is taken over: a new run starts from nothing of an earlier one; an extended
// one records its new end in config.toml (the earlier one is kept: set_aside_finished_results,
// or run.log for an interrupted run).
void claim_directory(RunDirectory& dir, RunMode mode, bool from_checkpoint, bool checksummed,
                     const std::string& resolved, const std::string& extension) {
  if (from_checkpoint)
    dir.remove_partial_files();
  else
    dir.remove_run_files(/*keep_log=*/mode == RunMode::resume);
  dir.start_log(this_command_line());
  if (!extension.empty()) std::fprintf(stderr, "%s\n", extension.c_str());
  if (from_checkpoint && !checksummed)
    std::fprintf(stderr,
                 "warning: %s has no checksum (written by an older sheardiff): resumed unchecked\n",
                 dir.file("checkpoint.bin").c_str());
  if (mode == RunMode::resume && !from_checkpoint)
    std::fprintf(stderr,
                 "%s: no checkpoint was written before the run stopped: starting again "
                 "from strain 0\n",
                 dir.path().c_str());
  if (!from_checkpoint || !extension.empty()) {
    write_file_atomically(dir.file("config.toml"), resolved);
  } else if (!std::filesystem::exists(dir.file("config.toml"))) {
    // The checkpoint holds the run's config and has been checked against this one: a deleted
    // config.toml is written again, so that the finished run can be analysed and swept.
    write_file_atomically(dir.file("config.toml"), resolved);
    std::fprintf(stderr, "%s was missing: written again (the checkpoint's configuration)\n",
                 dir.file("config.toml").c_str());
  }
}

// The end of the run. Every write replaces what an earlier attempt may have written (tables,
// analysis.h5, summary.json), so a death anywhere in it resumes from the last checkpoint and
// completes; summary.json, written last, marks the run finished.
template <class D>
nlohmann::json finish_run(const Config& cfg, RunningStateOf<D>& run, double elapsed_now,
                          RunDirectory& dir, TrajectoryOutputOf<D>& trajectory,
                          const CheckpointStoreOf<D>& checkpoints) {
  nlohmann::json js = run_summary(cfg, run, run.elapsed_before + elapsed_now, dir, trajectory);
  // The state at the end, kept so that the run can be extended (written before the summary:
  // a finished run always has it).
  checkpoints.save(run, elapsed_now, trajectory, dir.file(kFinalStateFile));
  trajectory.close();
  // channel.h5's writer does not check its file's close (analysis.h5's does since it throws on
  // a failed flush or close): a full disk there would leave a truncated file under the final
  // name, which HDF5 then refuses to open.
  for (const char* name : kAnalyserFiles) {
    const auto file = dir.file(name);
    if (std::filesystem::exists(file) && !hdf5_file_opens(file)) {
      std::filesystem::remove(file);
      const std::string reason = dir.hdf5_log() ? dir.hdf5_log()->last_os_reason() : "";
      throw IoError(fmt::format("cannot write {}: {}", file.string(),
                                reason.empty() ? "the file was left incomplete" : reason));
    }
  }
  write_file_atomically(dir.file("summary.json"), json_text(js) + "\n");
  // Finished: the summary marks the run complete and the checkpoint has served its purpose
  // (final_state.bin holds the end).
  std::filesystem::remove(dir.file("checkpoint.bin"));
  return js;
}

std::int64_t unix_seconds_now() {
  return std::chrono::duration_cast<std::chrono::seconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

namespace {

// A finished run's end state, read to extend it: an unreadable one leaves the finished run as it
// is (the advice to start again with --overwrite, right for a checkpoint, would delete it).
template <class D>
void load_final_state(RunningStateOf<D>& run, CheckpointPayload payload, const RunDirectory& dir,
                      const std::string& resolved) {
  try {
    CheckpointStoreOf<D>(dir.file(kFinalStateFile), resolved, dir.path().string())
        .load(run, std::move(payload));
  } catch (const CorruptCheckpoint& e) {
    throw CorruptCheckpoint(
        fmt::format("{}: the run cannot be extended; the finished run is left as it is ({})",
                    dir.file(kFinalStateFile).string(), e.what()));
  }
}

// An extension goes on from where the run is; a finished run's results are set aside first
// (refused, with nothing changed, when the new end is no further than where the run stopped).
template <class D>
std::string extension_note(const Config& cfg, const RunningStateOf<D>& run, RunDirectory& dir,
                           bool finished) {
  const double strain = run.sim.dynamics().strain();
  if (run.finished(cfg))
    throw ConfigError(fmt::format(
        "--resume {}: the run would stop where it is (strain {:.6g}): give a further end (for "
        "a pressure cell that has found its steady state, steady.measure_strain sets it)",
        dir.path().string(), strain));
  if (!finished)
    return fmt::format(
        "extended: the run goes on from strain {:.6g} to its new end (strain "
        "{:.6g}); config.toml holds the new configuration",
        strain, run.planned_end_strain(cfg));
  // The trajectory must be there to be continued: checked before anything is moved.
  if (cfg.output.trajectory) {
    long frames = -1;
    try {
      frames = count_h5md_frames(dir.file(kTrajectoryFile));
    } catch (const std::exception&) {
    }
    if (frames < run.frames)
      throw ConfigError(fmt::format(
          "--resume {}: {} is missing or holds fewer frames than the finished run wrote ({}), so "
          "the run cannot be extended; nothing was changed",
          dir.path().string(), kTrajectoryFile, run.frames));
  }
  const auto kept = set_aside_finished_results(dir, strain);
  return fmt::format(
      "extended: the finished run goes on from strain {:.6g} to its new end "
      "(strain {:.6g}); what it wrote when it finished is kept in {}",
      strain, run.planned_end_strain(cfg), kept.string());
}

}  // namespace

// A function-try-block: every failure of the run passes the handlers at the end.
namespace {

// Where a run's step loop sends what it produces: checkpoints, frames, progress lines; and how
// it stops (a signal, an unhealthy state) with a checkpoint.
template <class D>
class StepLoop {
 public:
  using Dynamics = DynamicsOf<D>;
  using StepView = StepViewOf<D>;

  StepLoop(const Config& cfg, RunningStateOf<D>& run, RunDirectory& dir,
           const CheckpointStoreOf<D>& checkpoints, TrajectoryOutputOf<D>& trajectory,
           RunProgress& progress)
      : cfg_(cfg),
        run_(run),
        dir_(dir),
        checkpoints_(checkpoints),
        trajectory_(trajectory),
        progress_(progress) {}

  void run_to_the_end() {
    auto& sim = run_.sim;
    Dynamics& d = sim.dynamics();
    if (d.steps() == 0 && run_.frames == 0) frame_at_rest();
    while (!run_.finished(cfg_)) {
      if (const int sig = g_stop_signal.load()) stop_on_signal(sig);
      d.set_landing(run_.next_frame);
      if (!sim.try_step()) stop(run_.health.solver_failure(d, sim.integrator().velocities()));
      if (auto r = run_.health.check(d, sim.integrator().velocities(), sim.integrator().last_dt()))
        stop(*r);
      const StressSample s = sim.sample();
      const StepView view{d, sim.integrator().velocities(), s, sim.integrator().last_dt(),
                          sim.integrator().stages(d)};
      for (const auto& o : run_.observers) o->on_step(view);
      if (d.strain() >= run_.next_frame * (1.0 - 1e-12)) output_frame(view);
      show_progress();
      trajectory_.flush_now_and_then();
    }
    // The last move may have used up the skin: check it against a fresh neighbour list.
    if (d.neighbours().needs_rebuild()) {
      d.rebuild_now();
      if (auto r = run_.health.check(d, sim.integrator().velocities(), sim.integrator().last_dt()))
        stop(*r);
    }
    progress_.end_line();
  }

 private:
  // The frame at step 0: the initial configuration with its velocities and stresses at rest
  // (solved, nothing moved). Observers give its values; none takes it as a sample of the flow.
  void frame_at_rest() {
    auto& sim = run_.sim;
    if (!sim.solve_at_rest())
      stop(run_.health.solver_failure(sim.dynamics(), sim.integrator().velocities()));
    const StressSample s = sim.sample_at_rest();
    write_frame(StepView{sim.dynamics(), sim.integrator().velocities(), s, 0.0,
                         sim.integrator().stages(sim.dynamics())});
  }

  // A frame: observers add their values, the trajectory writes it, a checkpoint may follow.
  void output_frame(const StepView& view) {
    const Dynamics& d = run_.sim.dynamics();
    run_.next_frame = next_output_strain(run_.next_frame, cfg_.output.frame_strain, d.strain());
    write_frame(view);
    if (cfg_.output.checkpoint_strain > 0.0 && d.strain() >= run_.next_checkpoint * (1.0 - 1e-12)) {
      run_.next_checkpoint =
          next_output_strain(run_.next_checkpoint, cfg_.output.checkpoint_strain, d.strain());
      checkpoints_.save(run_, progress_.elapsed(), trajectory_);
    }
  }

  void write_frame(const StepView& view) {
    values_.clear();
    for (const auto& o : run_.observers) o->on_frame(view, values_);
    trajectory_.write_frame(cfg_, run_, values_);
    ++run_.frames;
  }

  [[noreturn]] void stop_on_signal(int sig) {
    const Dynamics& d = run_.sim.dynamics();
    checkpoints_.save(run_, progress_.elapsed(), trajectory_);
    progress_.end_line();
    throw RunInterrupted(sig, fmt::format("stopped by signal {} at step {} (strain {:.6g}); "
                                          "checkpoint written: resume with `sheardiff run "
                                          "CONFIG --resume {}`",
                                          sig, d.steps(), d.strain(), dir_.path().string()));
  }

  // A run gone wrong stops with a checkpoint if its state is finite (else the last one is
  // kept) and a diagnostic frame.
  [[noreturn]] void stop(const HealthReport& r) {
    if (r.state_finite) checkpoints_.save(run_, progress_.elapsed(), trajectory_);
    write_diagnostic(dir_.file("diagnostic.txt"), run_.sim.dynamics(),
                     run_.sim.integrator().velocities(), r);
    progress_.end_line();
    throw RunUnhealthy(r);
  }

  void show_progress() {
    const Dynamics& d = run_.sim.dynamics();
    std::string more;
    for (const auto& o : run_.observers)
      if (const std::string words = o->progress(); !words.empty()) more += "  " + words;
    progress_.update(d.strain(), d.steps(), run_.planned_end_strain(cfg_), more);
  }

  const Config& cfg_;
  RunningStateOf<D>& run_;
  RunDirectory& dir_;
  const CheckpointStoreOf<D>& checkpoints_;
  TrajectoryOutputOf<D>& trajectory_;
  RunProgress& progress_;
  std::vector<double> values_;
};

// Once the run has taken charge of the directory (its log started), a failure to write leaves
// it resumable: the last checkpoint whole (it is never half-written), no FILE.tmp, and the user
// told how to go on.
[[noreturn]] void rethrow_with_advice(RunDirectory& dir, const IoError& e) {
  dir.remove_partial_files();
  const std::string out = dir.path().string();
  if (dir.moved())
    throw IoError(fmt::format(
        "{}. {} was moved or removed while the run ran; {}", e.what(), out,
        dir.state() == RunState::interrupted
            ? "its checkpoint.bin went with it: continue with `sheardiff run CONFIG --resume "
              "NEWDIR` where it is now"
            : "no checkpoint had been written: start the run again"));
  throw IoError(fmt::format(
      "{}. {}", e.what(),
      dir.state() == RunState::interrupted
          ? fmt::format("{} is intact: once the cause is fixed, continue with `sheardiff run "
                        "CONFIG --resume {}`",
                        dir.file("checkpoint.bin").string(), out)
          : fmt::format("No checkpoint was written yet: once the cause is fixed, `sheardiff run "
                        "CONFIG --resume {}` starts the run again",
                        out)));
}

// The run in its dimension, from where check_directory found it to its end.
template <class D>
nlohmann::json run_in(const Config& cfg, RunDirectory& dir, RunMode mode, Origin origin,
                      bool extending, const std::string& resolved, std::int64_t started,
                      bool progress, double progress_seconds) {
  const bool from_checkpoint = origin == Origin::checkpoint || origin == Origin::final_state;
  const CheckpointStoreOf<D> checkpoints(dir.file("checkpoint.bin"), resolved, dir.path().string());
  CheckpointPayload payload;
  if (from_checkpoint)
    payload = read_checkpoint_file(
        dir.file(origin == Origin::final_state ? kFinalStateFile : kCheckpointFile));
  // The initial state is built (and the checkpoint read) before anything is written: a bad
  // input file leaves no output.
  const bool checksummed = payload.checksummed;
  RunningStateOf<D> run(cfg, dir.path(), started);
  if (origin == Origin::final_state)
    load_final_state(run, std::move(payload), dir, resolved);
  else if (from_checkpoint)
    checkpoints.load(run, std::move(payload));
  const std::string extension =
      extending ? extension_note(cfg, run, dir, origin == Origin::final_state) : "";
  claim_directory(dir, mode, from_checkpoint, checksummed, resolved, extension);
  TrajectoryOutputOf<D> trajectory(cfg, run, dir, resolved, from_checkpoint);
  RunProgress progress_lines(dir, progress, progress_seconds, run.sim.dynamics().strain(),
                             run.sim.dynamics().steps());
  StepLoop<D>(cfg, run, dir, checkpoints, trajectory, progress_lines).run_to_the_end();
  return finish_run(cfg, run, progress_lines.elapsed(), dir, trajectory, checkpoints);
}

}  // namespace

nlohmann::json run_to_directory(const Config& given, RunDirectory& dir, RunMode mode, bool progress,
                                double progress_seconds) try {
  // From here SIGINT/SIGTERM only set a flag: a signal during the set-up (minutes for a large
  // packing) stops the run at step 0 with a checkpoint instead of leaving a bare directory.
  StopSignals signals;
  const std::int64_t started = unix_seconds_now();
  Config cfg = given;
  resolve_defaults(cfg);
  const std::string resolved = to_toml(cfg);
  bool extending = false;
  const Origin origin = check_directory(dir, mode, cfg, resolved, extending);
  if (origin == Origin::finished) return finished_run_summary(dir);
  return cfg.scene.dimension == 3 ? run_in<Dim3>(cfg, dir, mode, origin, extending, resolved,
                                                 started, progress, progress_seconds)
                                  : run_in<Dim2>(cfg, dir, mode, origin, extending, resolved,
                                                 started, progress, progress_seconds);
} catch (const IoError& e) {
  if (!dir.logging()) throw;
  rethrow_with_advice(dir, e);
} catch (...) {
  if (dir.logging()) dir.remove_partial_files();
  throw;
}

}  // namespace sheardiff
