#pragma once
// A run directory DIR and what keeps its results safe (docs/stability.md, "Run directories"):
// one process at a time (an advisory lock on DIR, held for the whole command), nothing of an
// existing run changed unless the command says so, and DIR/run.log, the log of everything the
// command printed and of HDF5's error stacks.
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace sheardiff {

// What DIR holds: no run file at all; a run stopped before its first checkpoint (config.toml,
// a partial trajectory, ...); an interrupted run (checkpoint.bin, no summary.json); a finished
// run (summary.json).
enum class RunState { empty, started, interrupted, finished };

// The files a run writes into DIR (and the FILE.tmp of each while it is written).
const std::vector<std::string>& run_file_names();

class Hdf5ErrorLog;

class RunDirectory {
 public:
  // Takes the lock of DIR, making DIR (and its parents) first if `create`. Throws ConfigError
  // if another process holds the lock (naming that process) or DIR is missing and !create,
  // IoError if DIR cannot be made or opened. Touches nothing in DIR.
  RunDirectory(std::filesystem::path dir, bool create);
  // Stops the log, removes DIR if this object made it and it is still empty, then unlocks.
  ~RunDirectory();
  RunDirectory(const RunDirectory&) = delete;
  RunDirectory& operator=(const RunDirectory&) = delete;

  const std::filesystem::path& path() const { return dir_; }
  std::filesystem::path file(const std::string& name) const { return dir_ / name; }
  RunState state() const;
  // Whether DIR no longer names the directory this object locked (it was renamed or removed
  // while the command ran); then state() reports what the moved directory holds.
  bool moved() const;
  // The run files present, for messages ("config.toml, trajectory.h5").
  std::string run_files_present() const;

  // Removes every run file (keep_log: all but run.log) and every FILE.tmp.
  void remove_run_files(bool keep_log);
  // Removes the FILE.tmp left by a writer that died or failed.
  void remove_partial_files();

  // From now until destruction, what the process writes to stdout and stderr also goes to
  // DIR/run.log (appended; a line redrawn with '\r', a terminal's live progress line, is not
  // logged), and so do HDF5's error stacks (instead of the terminal). `header` opens this
  // command's part of the log: "=== TIME (ISO 8601 UTC) on HOST, pid PID, sheardiff VERSION
  // (git HASH): header".
  void start_log(const std::string& header);
  // Whether start_log was called: this command has taken charge of DIR.
  bool logging() const { return tee_ != nullptr; }
  // Whether the command's stderr (before start_log redirected it) is a terminal.
  bool terminal() const;
  // Appends text to run.log only, not to the terminal, in order after what was printed before
  // (nothing before start_log).
  void log_only(std::string_view text);
  // HDF5 errors seen since start_log (null before it).
  const Hdf5ErrorLog* hdf5_log() const { return hdf5_log_.get(); }
  // Runs f. Some writers (analysis.h5) report a failed HDF5 write as a bare runtime_error: one
  // thrown while HDF5 logged an error is rethrown as IoError with the operating system reason.
  void with_hdf5_reasons(const std::function<void()>& f) const;

 private:
  class OutputTee;
  std::filesystem::path dir_;
  int fd_ = -1;  // DIR itself, flock'ed
  bool created_ = false;
  std::FILE* hdf5_log_file_ = nullptr;
  std::unique_ptr<Hdf5ErrorLog> hdf5_log_;
  std::unique_ptr<OutputTee> tee_;
};

// "sheardiff run x.toml --out DIR" of this process, for log headers.
std::string this_command_line();

}  // namespace sheardiff
