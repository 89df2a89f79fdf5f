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

#include "sheardiff/config.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/io_error.hpp"
#include "sheardiff/io/run_directory.hpp"
#include "sheardiff/io/text.hpp"
#include "sheardiff/simulation.hpp"
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

int run_local(const SweepSpec& spec, const fs::path& out_dir, int jobs, const fs::path& exe,
              bool progress_lines) {
  const auto points = expand_points(spec);
  fs::create_directories(out_dir / "points");
  fs::create_directories(out_dir / "logs");
  const FileLock lock(out_dir / "sweep.lock", "the sweep in " + out_dir.string());
  if (const std::string w = oversubscription_warning(jobs, threads_per_worker(), usable_cores());
      !w.empty())
    fmt::print(stderr, "{}\n", w);

  // States first (a foreign directory stops the sweep before anything starts), longest first.
  std::vector<const SweepPoint*> todo, elsewhere;
  long finished_before = 0;
  std::error_code ec;
  for (const auto& p : points) {
    if (point_state(spec, p, out_dir) == PointState::finished) {
      ++finished_before;
      // A failure recorded by an earlier attempt no longer describes the point.
      fs::remove(out_dir / "logs" / (p.name + ".failed"), ec);
    } else if (locked_elsewhere(point_lock(out_dir, p))) {
      elsewhere.push_back(&p);
    } else {
      todo.push_back(&p);
    }
  }
  // Workers of an earlier pool that was killed (SIGKILL, a lost terminal) still run their
  // points: they are waited for, not started twice nor counted as failed.
  if (!elsewhere.empty())
    fmt::print(stderr,
               "sweep: {} point(s) are being run by other processes (the workers of an earlier "
               "sweep whose pool was stopped?): waiting for them, not starting them again\n",
               elsewhere.size());
  std::stable_sort(todo.begin(), todo.end(),
                   [](const SweepPoint* a, const SweepPoint* b) { return a->cost > b->cost; });
  std::reverse(todo.begin(), todo.end());  // taken from the back

  // Signals are taken synchronously (sigtimedwait), so no handler and no global flag: SIGCHLD
  // says a worker ended, SIGINT/SIGTERM are forwarded to the workers, which checkpoint.
  sigset_t mask, old_mask;
  sigemptyset(&mask);
  sigaddset(&mask, SIGCHLD);
  sigaddset(&mask, SIGINT);
  sigaddset(&mask, SIGTERM);
  sigprocmask(SIG_BLOCK, &mask, &old_mask);
  sigset_t child_mask;
  sigemptyset(&child_mask);

  // Off a terminal (a batch log), the pool's lines start with an ISO 8601 UTC timestamp.
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto stamp = [tty] { return tty ? std::string() : iso8601_utc_now() + "  "; };
  std::map<pid_t, Worker> running;
  long done = 0, failed = 0;
  double done_cost = 0, done_seconds = 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto last_print = t0 - std::chrono::hours(1);
  bool changed = true;
  int stop_signal = 0;

  const auto spawn = [&](const SweepPoint* p) {
    const std::string log = (out_dir / "logs" / (p->name + ".log")).string();
    const std::string index = std::to_string(p->index);
    const std::string file = spec.file.string(), out = out_dir.string(), self = exe.string();
    std::vector<char*> argv = {const_cast<char*>(self.c_str()),  const_cast<char*>("sweep"),
                               const_cast<char*>(file.c_str()),  const_cast<char*>("--out"),
                               const_cast<char*>(out.c_str()),   const_cast<char*>("--point"),
                               const_cast<char*>(index.c_str()), nullptr};
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
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
    running[pid] = {p, std::chrono::steady_clock::now()};
  };

  const auto reap = [&] {
    int status = 0;
    pid_t pid;
    while ((pid = waitpid(-1, &status, WNOHANG)) > 0) {
      auto it = running.find(pid);
      if (it == running.end()) continue;
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      const double secs =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - it->second.started)
              .count();
      const auto& p = *it->second.point;
      if (code == 0) {
        ++done;
        done_cost += p.cost;
        done_seconds += secs;
      } else if (!stop_signal && locked_elsewhere(point_lock(out_dir, p))) {
        // Taken by another process between the check and the start: waited for like the others.
        elsewhere.push_back(&p);
      } else if (!stop_signal) {
        ++failed;
        fmt::print(stderr, "{}sweep: point {} failed (exit {}) after {}; see {}\n", stamp(), p.name,
                   code, duration_text(secs), (out_dir / "logs" / (p.name + ".log")).string());
      }
      running.erase(it);
      changed = true;
    }
  };

  const auto progress = [&] {
    if (!progress_lines) return;
    const auto now = std::chrono::steady_clock::now();
    if (!changed && now - last_print < std::chrono::seconds(30)) return;
    const double elapsed = std::chrono::duration<double>(now - t0).count();
    // Seconds per unit of cost from the points finished so far; a running point is charged
    // what its estimate has left (at least a tenth of it: estimates are rough).
    std::string eta = "?";
    if (done > 0) {
      const double rate = done_seconds / done_cost;
      double left = 0;
      for (const auto* p : todo) left += p->cost * rate;
      for (const auto& [pid, w] : running) {
        const double est = w.point->cost * rate;
        left += std::max(est - std::chrono::duration<double>(now - w.started).count(), 0.1 * est);
      }
      eta = duration_text(left / jobs);
    }
    fmt::print(stderr,
               "{}sweep: {}/{} done ({} before this start, {} failed), {} running, {} to go; "
               "{} elapsed, ETA {}\n",
               stamp(), finished_before + done, points.size(), finished_before, failed,
               running.size() + elsewhere.size(), todo.size(), duration_text(elapsed), eta);
    last_print = now;
    changed = false;
  };

  // A point run elsewhere is checked at each tick: once its lock is free it is finished (done)
  // or goes back to the queue (it resumes from its checkpoint).
  const auto poll_elsewhere = [&] {
    for (auto it = elsewhere.begin(); it != elsewhere.end();) {
      if (locked_elsewhere(point_lock(out_dir, **it))) {
        ++it;
        continue;
      }
      if (point_state(spec, **it, out_dir) == PointState::finished) {
        ++finished_before;
        fs::remove(out_dir / "logs" / ((*it)->name + ".failed"), ec);
      } else {
        todo.insert(todo.begin(), *it);
      }
      it = elsewhere.erase(it);
      changed = true;
    }
  };

  while (!todo.empty() || !running.empty() || (!elsewhere.empty() && !stop_signal)) {
    poll_elsewhere();
    while (!stop_signal && static_cast<int>(running.size() + elsewhere.size()) < jobs &&
           !todo.empty()) {
      spawn(todo.back());
      todo.pop_back();
      changed = true;
    }
    progress();
    if (stop_signal && running.empty()) break;
    const timespec wait{2, 0};
    const int sig = sigtimedwait(&mask, nullptr, &wait);
    if ((sig == SIGINT || sig == SIGTERM) && !stop_signal) {
      stop_signal = sig;
      fmt::print(stderr, "{}sweep: signal {}: stopping {} running point(s) at their checkpoint\n",
                 stamp(), sig, running.size());
      for (const auto& [pid, w] : running) kill(pid, SIGTERM);
    }
    reap();
    if (stop_signal && running.empty()) break;
  }
  if (!stop_signal) progress();  // the last line: every point done, when
  sigprocmask(SIG_SETMASK, &old_mask, nullptr);
  if (stop_signal)
    throw RunInterrupted(stop_signal,
                         fmt::format("sweep stopped by signal {}: run the same command again to "
                                     "continue (finished points are kept, the others resume)",
                                     stop_signal));
  return static_cast<int>(failed);
}

}  // namespace sheardiff
