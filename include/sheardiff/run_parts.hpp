#pragma once
// The parts a run in a directory is made of (run_to_directory, src/run.cpp composes them):
// the evolving state of the run and its checkpoint store, the trajectory output, the progress
// lines and the summary.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sheardiff/engine.hpp"
#include "sheardiff/io/checkpoint_file.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/io/run_directory.hpp"
#include "sheardiff/observe/observer.hpp"
#include "sheardiff/observe/run_health.hpp"
#include "sheardiff/scene/registry.hpp"

namespace sheardiff {

// Everything of a run that evolves: the simulation, its health checks and observers, and the
// bookkeeping of its outputs; in the run's dimension D (scene.dimension).
template <class D>
struct RunningStateOf {
  RunningStateOf(const Config& cfg, const std::filesystem::path& out_dir, std::int64_t started_at);

  SimulationOf<D> sim;
  RunHealthOf<D> health;
  ObserverListOf<D> observers;
  double next_frame, next_checkpoint;
  double elapsed_before = 0.0;  // seconds run before this process (a resumed run)
  long frames = 0;
  // When the run started (a resumed run: its first start), as Unix seconds; -1: unknown.
  std::int64_t started;

  DynamicsOf<D>& dynamics() { return sim.dynamics(); }
  // Whether an observer, run.strain or run.max_steps ends the run now.
  bool finished(const Config& cfg) const;
  // The strain the run will end at, as far as it is known now (the progress line's end).
  double planned_end_strain(const Config& cfg) const;
};

// The trajectory (H5MD) of a run, or nothing with output.trajectory = false.
template <class D>
class TrajectoryOutputOf {
 public:
  // resume: append to the file cut back to the checkpoint's frames.
  TrajectoryOutputOf(const Config& cfg, const RunningStateOf<D>& run, const RunDirectory& dir,
                     const std::string& resolved, bool resume);
  void write_frame(const Config& cfg, const RunningStateOf<D>& run,
                   const std::vector<double>& values);
  void flush() {
    if (writer_) writer_->flush();
  }
  // Every two seconds: a killed run leaves readable frames, and readers following the file
  // (single-writer/multiple-reader mode) see a frame at most that late.
  void flush_now_and_then();
  H5mdWriter* writer() { return writer_.get(); }
  void close();

 private:
  std::unique_ptr<H5mdWriter> writer_;
  std::chrono::steady_clock::time_point last_flush_ = std::chrono::steady_clock::now();
};

// checkpoint.bin: the whole RunningState in one fixed order, written atomically, read back
// bit-identically; refused if it was written for another configuration.
template <class D>
class CheckpointStoreOf {
 public:
  CheckpointStoreOf(std::filesystem::path file, std::string resolved_config, std::string out_dir)
      : file_(std::move(file)), resolved_(std::move(resolved_config)), out_(std::move(out_dir)) {}
  // Throws ConfigError (another configuration, but one that only moves the run's end) or
  // CorruptCheckpoint.
  void load(RunningStateOf<D>& run, CheckpointPayload payload) const;
  // elapsed_now: seconds this process has run; the trajectory is flushed first so that it holds
  // every frame the checkpoint counts. To file() unless another file is given (the final state).
  void save(RunningStateOf<D>& run, double elapsed_now, TrajectoryOutputOf<D>& trajectory,
            const std::filesystem::path& to = {}) const;
  const std::filesystem::path& file() const { return file_; }

 private:
  void serialize(Archive& a, RunningStateOf<D>& run, int layout) const;
  std::filesystem::path file_;
  std::string resolved_, out_;
};

// Progress on stderr: a live line redrawn on a terminal (not logged), and a timestamped line
// every `seconds` off a terminal, or in run.log alone (a terminal, --quiet).
class RunProgress {
 public:
  // strain, steps: where this process starts from (a resumed run's checkpoint), so that the
  // rate and the ETA count only the steps taken since.
  RunProgress(RunDirectory& dir, bool progress, double seconds, double strain, long steps);
  // Seconds since this process started the run.
  double elapsed() const;
  // end: the strain the run will end at, as far as it is known now; more: the observers' words.
  void update(double strain, long steps, double end, const std::string& more);
  // Ends a live line before anything else is printed.
  void end_line();

 private:
  RunDirectory& dir_;
  bool progress_, tty_;
  double seconds_;
  std::chrono::steady_clock::time_point t0_, last_print_, last_line_;
  double strain0_;
  long steps0_;
  bool shown_ = false;
};

// summary.json of a finished run: who ran what, the step statistics, and every observer's and
// the health checks' results (observers may also write tables into the trajectory).
template <class D>
nlohmann::json run_summary(const Config& cfg, RunningStateOf<D>& run, double wall_seconds,
                           RunDirectory& dir, TrajectoryOutputOf<D>& trajectory);

// The observers the scene and the config ask for (and only those), in their update order: what
// the scene measures (SceneKind::measures) decides which.
template <class D>
ObserverListOf<D> make_observers_of(const SceneKind& scene, const Config& cfg,
                                    const std::filesystem::path& out_dir);
inline ObserverList make_observers(const SceneKind& scene, const Config& cfg,
                                   const std::filesystem::path& out_dir) {
  return make_observers_of<Dim2>(scene, cfg, out_dir);
}
ObserverList make_observers(const Config& cfg, const std::filesystem::path& out_dir);

// The disc names (the 2D instantiation).
using RunningState = RunningStateOf<Dim2>;
using TrajectoryOutput = TrajectoryOutputOf<Dim2>;
using CheckpointStore = CheckpointStoreOf<Dim2>;

}  // namespace sheardiff
