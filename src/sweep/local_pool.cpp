// Running sweep points: one point in this process, or a pool of worker processes.
#include <fcntl.h>
#include <fmt/format.h>
#include <sched.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <optional>
#include <set>

#include "sheardiff/config.hpp"
#include "sheardiff/core/text.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/io_error.hpp"
#include "sheardiff/io/run_directory.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/sweep/sweep.hpp"

extern char** environ;

namespace sheardiff {
namespace fs = std::filesystem;

namespace {

// An exclusive lock on FILE held for the lifetime of this object (released by the kernel if the
// process dies): two processes must never run the same point or pool the same sweep folder.
class FileLock {
 public:
  FileLock(const fs::path& file, const std::string& what) {
    fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) throw_io_error("open the lock file", file);
    if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd_);
      throw ConfigError(
          fmt::format("{} is already being run by another process (lock {})", what, file.string()));
    }
  }
  ~FileLock() { ::close(fd_); }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_ = -1;
};

// Whether another process holds the lock of FILE now (a worker of an earlier sweep whose pool
// was killed keeps its point's lock until it ends).
bool locked_elsewhere(const fs::path& file) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  ::close(fd);  // releases it if this probe took it
  return held;
}

fs::path point_lock(const fs::path& out_dir, const SweepPoint& p) {
  return out_dir / "logs" / (p.name + ".lock");
}

}  // namespace

void run_point(const SweepSpec& spec, const SweepPoint& p, const fs::path& out_dir,
               const std::function<void(const RunDirectory&, const nlohmann::json&)>& report) {
  fs::create_directories(out_dir / "logs");
  // Held by another process: that process runs the point, which is not a failure of it.
  std::optional<FileLock> lock;
  try {
    lock.emplace(point_lock(out_dir, p), "sweep point " + p.name);
  } catch (const ConfigError& e) {
    throw PointBusy(e.what());
  }
  const auto state = point_state(spec, p, out_dir);
  if (state == PointState::finished) return;
  const Config cfg = load_config(spec.base, p.overrides);
  // A fresh point may hold the remains of a start killed before its first checkpoint: nothing
  // in it can be continued, and a stale trajectory must not survive into the new run
  // (overwrite removes it, under the run directory's own lock).
  RunDirectory dir(point_dir(out_dir, p), true);
  // ... unless it holds what such a start cannot have left: its summary or checkpoint was moved.
  if (state == PointState::fresh)
    if (const auto lost = restart_would_lose(dir, cfg); !lost.empty())
      throw ConfigError("sweep point " + p.name + ": " + lost);
  const nlohmann::json summary = run_to_directory(
      cfg, dir, state == PointState::resumable ? RunMode::resume : RunMode::overwrite, true);
  // While the run directory's log is open: the result goes to its run.log and to the point's
  // log of the pool (the worker's output).
  if (report) report(dir, summary);
  export_point(spec, p, out_dir);
}

namespace {

struct Worker {
  const SweepPoint* point;
  std::chrono::steady_clock::time_point started;
};

// Cores this process may run on (its affinity mask: a cgroup or taskset limit counts).
int usable_cores() {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof(set), &set) == 0) return CPU_COUNT(&set);
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? static_cast<int>(n) : 1;
}

int threads_per_worker() {
  const char* limit = std::getenv("OMP_THREAD_LIMIT");
  if (limit == nullptr) return 1;  // sheardiff sets 1 when it is unset (src/app/main.cpp)
  const int t = std::atoi(limit);
  return t > 0 ? t : 1;
}

}  // namespace

std::string oversubscription_warning(int jobs, int threads_per_job, int cores) {
  if (static_cast<long>(jobs) * threads_per_job <= cores) return {};
  const int fit = std::max(1, cores / std::max(1, threads_per_job));
  return fmt::format(
      "sweep: warning: --jobs {} x OMP_THREAD_LIMIT {} = {} threads on {} cores; the workers will "
      "share cores, each point runs slower and the sweep does not finish sooner. Use --jobs {} "
      "(docs/performance.md, \"Threads\").",
      jobs, threads_per_job, static_cast<long>(jobs) * threads_per_job, cores, fit);
}

namespace {

// SIGCHLD, SIGINT and SIGTERM blocked for the pool's lifetime: they are taken synchronously
// (sigtimedwait), so no handler and no global flag. Restored on every exit path.
class BlockedSignals {
 public:
  BlockedSignals() {
    sigemptyset(&set_);
    sigaddset(&set_, SIGCHLD);
    sigaddset(&set_, SIGINT);
    sigaddset(&set_, SIGTERM);
    sigprocmask(SIG_BLOCK, &set_, &old_);
  }
  ~BlockedSignals() { sigprocmask(SIG_SETMASK, &old_, nullptr); }
  BlockedSignals(const BlockedSignals&) = delete;
  BlockedSignals& operator=(const BlockedSignals&) = delete;
  // The next of them within `seconds`, or -1.
  int wait(long seconds) const {
    const timespec t{seconds, 0};
    return sigtimedwait(&set_, nullptr, &t);
  }

 private:
  sigset_t set_{}, old_{};
};

// The pool of one `sweep` command: points to run (part-run first, then longest first), points
// that workers of an earlier pool still run, the workers it started, and what it has counted.
class WorkerPool {
 public:
  WorkerPool(const SweepSpec& spec, const fs::path& out_dir, int jobs, const fs::path& exe,
             bool progress_lines)
      : spec_(spec),
        out_dir_(out_dir),
        jobs_(jobs),
        exe_(exe),
        progress_lines_(progress_lines),
        points_(expand_points(spec)) {}

  int run();

 private:
  void sort_points();
  void spawn(const SweepPoint* p);
  void reap();
  void progress();
  void poll_elsewhere();
  void forget_failure(const SweepPoint& p) {
    std::error_code ec;
    fs::remove(out_dir_ / "logs" / (p.name + ".failed"), ec);
  }
  // Off a terminal (a batch log), the pool's lines start with an ISO 8601 UTC timestamp.
  std::string stamp() const { return tty_ ? std::string() : iso8601_utc_now() + "  "; }

  const SweepSpec& spec_;
  const fs::path out_dir_;
  const int jobs_;
  const fs::path exe_;
  const bool progress_lines_;
  const std::vector<SweepPoint> points_;
  const bool tty_ = isatty(STDERR_FILENO) != 0;
  std::vector<const SweepPoint*> todo_, elsewhere_;
  std::map<pid_t, Worker> running_;
  long finished_before_ = 0, done_ = 0, failed_ = 0;
  double done_cost_ = 0, done_seconds_ = 0;
  const std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_print_ = t0_ - std::chrono::hours(1);
  bool changed_ = true;
  int stop_signal_ = 0;
};

// States first (a foreign directory stops the sweep before anything starts); part-run points
// first, then the longest.
void WorkerPool::sort_points() {
  std::set<const SweepPoint*> part_run;
  for (const auto& p : points_) {
    const PointState state = point_state(spec_, p, out_dir_);
    if (state == PointState::finished) {
      ++finished_before_;
      forget_failure(p);  // a failure recorded by an earlier attempt no longer describes it
    } else if (locked_elsewhere(point_lock(out_dir_, p))) {
      elsewhere_.push_back(&p);
    } else {
      todo_.push_back(&p);
      if (state == PointState::resumable) part_run.insert(&p);
    }
  }
  // Workers of an earlier pool that was killed (SIGKILL, a lost terminal) still run their
  // points: they are waited for, not started twice nor counted as failed.
  if (!elsewhere_.empty())
    fmt::print(stderr,
               "sweep: {} point(s) are being run by other processes (the workers of an earlier "
               "sweep whose pool was stopped?): waiting for them, not starting them again\n",
               elsewhere_.size());
  // Part-run points first, so that a sweep started again finishes what it had begun (their
  // results land, their checkpoints go) before it begins more; then the costliest first.
  std::stable_sort(todo_.begin(), todo_.end(), [&](const SweepPoint* a, const SweepPoint* b) {
    const bool ra = part_run.contains(a), rb = part_run.contains(b);
    return ra != rb ? ra : a->cost > b->cost;
  });
  std::reverse(todo_.begin(), todo_.end());  // taken from the back
}

// A worker is this executable running `sweep FILE --out DIR --point I`, its output appended to
// the point's log, with no signal blocked (it checkpoints on SIGTERM).
void WorkerPool::spawn(const SweepPoint* p) {
  const std::string log = (out_dir_ / "logs" / (p->name + ".log")).string();
  const std::string index = std::to_string(p->index);
  const std::string file = spec_.file.string(), out = out_dir_.string(), self = exe_.string();
  std::vector<char*> argv = {const_cast<char*>(self.c_str()),  const_cast<char*>("sweep"),
                             const_cast<char*>(file.c_str()),  const_cast<char*>("--out"),
                             const_cast<char*>(out.c_str()),   const_cast<char*>("--point"),
                             const_cast<char*>(index.c_str()), nullptr};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  sigset_t child_mask;
  sigemptyset(&child_mask);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setsigmask(&attr, &child_mask);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, self.c_str(), &fa, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  posix_spawnattr_destroy(&attr);
  if (rc != 0)
    throw std::runtime_error(fmt::format("sweep: cannot start {}: {}", self, std::strerror(rc)));
  running_[pid] = {p, std::chrono::steady_clock::now()};
  changed_ = true;
}

void WorkerPool::reap() {
  int status = 0;
  pid_t pid;
  while ((pid = waitpid(-1, &status, WNOHANG)) > 0) {
    auto it = running_.find(pid);
    if (it == running_.end()) continue;
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    const double secs =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second.started)
            .count();
    const auto& p = *it->second.point;
    if (code == 0) {
      ++done_;
      done_cost_ += p.cost;
      done_seconds_ += secs;
    } else if (!stop_signal_ && locked_elsewhere(point_lock(out_dir_, p))) {
      // Taken by another process between the check and the start: waited for like the others.
      elsewhere_.push_back(&p);
    } else if (!stop_signal_) {
      ++failed_;
      fmt::print(stderr, "{}sweep: point {} failed (exit {}) after {}; see {}\n", stamp(), p.name,
                 code, duration_text(secs), (out_dir_ / "logs" / (p.name + ".log")).string());
    }
    running_.erase(it);
    changed_ = true;
  }
}

void WorkerPool::progress() {
  if (!progress_lines_) return;
  const auto now = std::chrono::steady_clock::now();
  if (!changed_ && now - last_print_ < std::chrono::seconds(30)) return;
  const double elapsed = std::chrono::duration<double>(now - t0_).count();
  // Seconds per unit of cost from the points finished so far; a running point is charged
  // what its estimate has left (at least a tenth of it: estimates are rough).
  std::string eta = "?";
  if (done_ > 0) {
    const double rate = done_seconds_ / done_cost_;
    double left = 0;
    for (const auto* p : todo_) left += p->cost * rate;
    for (const auto& [pid, w] : running_) {
      const double est = w.point->cost * rate;
      left += std::max(est - std::chrono::duration<double>(now - w.started).count(), 0.1 * est);
    }
    eta = duration_text(left / jobs_);
  }
  fmt::print(stderr,
             "{}sweep: {}/{} done ({} before this start, {} failed), {} running, {} to go; "
             "{} elapsed, ETA {}\n",
             stamp(), finished_before_ + done_, points_.size(), finished_before_, failed_,
             running_.size() + elsewhere_.size(), todo_.size(), duration_text(elapsed), eta);
  last_print_ = now;
  changed_ = false;
}

// A point run elsewhere is checked at each tick: once its lock is free it is finished (done)
// or goes back to the queue: next if it has a checkpoint to resume from, else last.
void WorkerPool::poll_elsewhere() {
  for (auto it = elsewhere_.begin(); it != elsewhere_.end();) {
    if (locked_elsewhere(point_lock(out_dir_, **it))) {
      ++it;
      continue;
    }
    const PointState state = point_state(spec_, **it, out_dir_);
    if (state == PointState::finished) {
      ++finished_before_;
      forget_failure(**it);
    } else if (state == PointState::resumable) {
      todo_.push_back(*it);
    } else {
      todo_.insert(todo_.begin(), *it);
    }
    it = elsewhere_.erase(it);
    changed_ = true;
  }
}

// SIGCHLD says a worker ended; SIGINT/SIGTERM are forwarded to the workers, which checkpoint.
int WorkerPool::run() {
  fs::create_directories(out_dir_ / "points");
  fs::create_directories(out_dir_ / "logs");
  const FileLock lock(out_dir_ / "sweep.lock", "the sweep in " + out_dir_.string());
  if (const std::string w = oversubscription_warning(jobs_, threads_per_worker(), usable_cores());
      !w.empty())
    fmt::print(stderr, "{}\n", w);
  sort_points();
  const BlockedSignals signals;
  while (!todo_.empty() || !running_.empty() || (!elsewhere_.empty() && !stop_signal_)) {
    poll_elsewhere();
    while (!stop_signal_ && static_cast<int>(running_.size() + elsewhere_.size()) < jobs_ &&
           !todo_.empty()) {
      spawn(todo_.back());
      todo_.pop_back();
    }
    progress();
    if (stop_signal_ && running_.empty()) break;
    const int sig = signals.wait(2);
    if ((sig == SIGINT || sig == SIGTERM) && !stop_signal_) {
      stop_signal_ = sig;
      fmt::print(stderr, "{}sweep: signal {}: stopping {} running point(s) at their checkpoint\n",
                 stamp(), sig, running_.size());
      for (const auto& [pid, w] : running_) kill(pid, SIGTERM);
    }
    reap();
    if (stop_signal_ && running_.empty()) break;
  }
  if (stop_signal_)
    throw RunInterrupted(stop_signal_,
                         fmt::format("sweep stopped by signal {}: run the same command again to "
                                     "continue (finished points are kept, the others resume)",
                                     stop_signal_));
  progress();  // the last line: every point done, when
  return static_cast<int>(failed_);
}

}  // namespace

int run_local(const SweepSpec& spec, const fs::path& out_dir, int jobs, const fs::path& exe,
              bool progress_lines) {
  return WorkerPool(spec, out_dir, jobs, exe, progress_lines).run();
}

}  // namespace sheardiff
