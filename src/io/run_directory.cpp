#include "sheardiff/io/run_directory.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <thread>

#include "sheardiff/config.hpp"
#include "sheardiff/core/text.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/hdf5_diagnostics.hpp"
#include "sheardiff/io/io_error.hpp"
#include "sheardiff/io/run_files.hpp"
#include "sheardiff/version.hpp"

namespace sheardiff {

namespace fs = std::filesystem;

namespace {

const char* const kLog = "run.log";

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// The process holding a flock on the file or directory `fd` is listed in /proc/locks as
// "N: FLOCK ADVISORY WRITE PID MAJ:MIN:INODE 0 EOF" (major and minor in hex).
std::string lock_holder(int fd) {
  struct stat st {};
  if (fstat(fd, &st) != 0) return "another process";
  const std::string id = fmt::format("{:02x}:{:02x}:{}", major(st.st_dev), minor(st.st_dev),
                                     static_cast<unsigned long>(st.st_ino));
  std::ifstream locks("/proc/locks");
  std::string line;
  while (std::getline(locks, line)) {
    if (line.find("->") != std::string::npos) continue;  // a waiter, not the holder
    std::istringstream ls(line);
    std::vector<std::string> words;
    for (std::string w; ls >> w;) words.push_back(w);
    for (std::size_t k = 1; k < words.size(); ++k) {
      if (words[k] != id) continue;
      const std::string pid = words[k - 1];
      std::string cmd = read_text(fs::path("/proc") / pid / "cmdline");
      for (char& c : cmd)
        if (c == '\0') c = ' ';
      while (!cmd.empty() && cmd.back() == ' ') cmd.pop_back();
      return cmd.empty() ? fmt::format("process {}", pid)
                         : fmt::format("process {} ({})", pid, cmd);
    }
  }
  return "another process";
}

}  // namespace

std::string this_command_line() {
  std::string cmd = read_text("/proc/self/cmdline");
  for (char& c : cmd)
    if (c == '\0') c = ' ';
  while (!cmd.empty() && cmd.back() == ' ') cmd.pop_back();
  return cmd;
}

const std::vector<std::string>& run_file_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {kConfigFile, kTrajectoryFile};
    n.insert(n.end(), kAnalyserFiles.begin(), kAnalyserFiles.end());
    for (const char* f : {kSummaryFile, kCheckpointFile, kFinalStateFile, kDiagnosticFile, kLog,
                          kReanalysisFolder, kEarlierFolder})
      n.emplace_back(f);
    return n;
  }();
  return names;
}

// Copies what the process writes to fds 1 and 2 to where they went before and to the log, by
// a thread reading two pipes: libraries (CHOLMOD's warnings) write to fd 2 directly. A line
// redrawn with '\r' (a terminal's live progress line) goes to the terminal only.
class RunDirectory::OutputTee {
 public:
  explicit OutputTee(int log_fd) : log_fd_(log_fd) {
    std::cout.flush();
    std::fflush(stdout);
    std::fflush(stderr);
    // Both pipes first: a failure must not leave one of fds 1 and 2 redirected.
    int p[2][2];
    if (pipe2(p[0], O_CLOEXEC) != 0) throw_io_error("create a pipe for", "run.log");
    if (pipe2(p[1], O_CLOEXEC) != 0) {
      const int err = errno;
      for (int fd : p[0]) ::close(fd);
      throw_io_error("create a pipe for", "run.log", err);
    }
    for (int k = 0; k < 2; ++k) {
      saved_[k] = fcntl(k + 1, F_DUPFD_CLOEXEC, 3);
      dup2(p[k][1], k + 1);
      ::close(p[k][1]);
      read_[k] = p[k][0];
    }
    // Signals stay with the main thread: its SIGINT/SIGTERM handler writes the checkpoint.
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old);
    thread_ = std::thread([this] { pump(); });
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
  }
  ~OutputTee() {
    std::cout.flush();
    std::fflush(stdout);
    std::fflush(stderr);
    // The pipes' only write ends are fds 1 and 2: restoring them ends the pump.
    for (int k = 0; k < 2; ++k) {
      if (saved_[k] >= 0)
        dup2(saved_[k], k + 1);
      else
        ::close(k + 1);  // it was closed before
    }
    if (thread_.joinable()) thread_.join();
    for (int k = 0; k < 2; ++k) {
      if (saved_[k] >= 0) ::close(saved_[k]);
      ::close(read_[k]);
    }
    ::close(log_fd_);
  }
  OutputTee(const OutputTee&) = delete;
  OutputTee& operator=(const OutputTee&) = delete;

  // Whether stderr, before the tee, was a terminal.
  bool terminal() const { return saved_[1] >= 0 && isatty(saved_[1]); }

  // Appends `text` to the log only, after everything printed before it.
  void log_only(std::string_view text) {
    std::cout.flush();
    std::fflush(stdout);
    std::fflush(stderr);
    // The pump reads and handles each chunk under the mutex: with the mutex held and both
    // pipes empty, all that was printed before is in the log.
    for (;;) {
      std::unique_lock lock(mutex_);
      int waiting[2] = {0, 0};
      for (int k = 0; k < 2; ++k)
        if (ioctl(read_[k], FIONREAD, &waiting[k]) != 0) waiting[k] = 0;
      if (waiting[0] == 0 && waiting[1] == 0) {
        write_all(log_fd_, text.data(), text.size());
        return;
      }
      lock.unlock();
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  }

 private:
  void pump() {
    pollfd fds[2] = {{read_[0], POLLIN, 0}, {read_[1], POLLIN, 0}};
    int open = 2;
    char buf[4096];
    while (open > 0) {
      if (poll(fds, 2, -1) < 0) {
        if (errno == EINTR) continue;
        break;
      }
      for (int k = 0; k < 2; ++k) {
        if (fds[k].fd < 0 || fds[k].revents == 0) continue;
        const std::lock_guard lock(mutex_);
        const ssize_t n = ::read(fds[k].fd, buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
          if (!line_[k].empty() && !live_[k]) log_line(k);
          fds[k].fd = -1;
          --open;
          continue;
        }
        if (saved_[k] >= 0) write_all(saved_[k], buf, static_cast<std::size_t>(n));
        // A line redrawn after '\r' (a terminal's live progress, twice a second) is not
        // logged: the log gets timestamped progress lines instead (run.cpp).
        for (ssize_t i = 0; i < n; ++i) {
          if (buf[i] == '\r') {
            line_[k].clear();
            live_[k] = true;
          } else if (buf[i] == '\n') {
            if (!live_[k]) log_line(k);
            line_[k].clear();
            live_[k] = false;
          } else {
            line_[k] += buf[i];
          }
        }
      }
    }
  }
  void log_line(int k) {
    line_[k] += '\n';
    write_all(log_fd_, line_[k].data(), line_[k].size());
    line_[k].clear();
  }

  int log_fd_;
  int saved_[2] = {-1, -1};
  int read_[2] = {-1, -1};
  std::string line_[2];
  bool live_[2] = {false, false};  // the line being read began with '\r'
  std::mutex mutex_;               // held by the pump while it handles a chunk
  std::thread thread_;
};

RunDirectory::RunDirectory(fs::path dir, bool create) : dir_(std::move(dir)) {
  std::error_code ec;
  if (!fs::exists(dir_, ec)) {
    if (!create) throw ConfigError(fmt::format("{}: no such directory", dir_.string()));
    fs::create_directories(dir_, ec);
    if (ec)
      throw IoError(fmt::format("cannot create the directory {}: {}", dir_.string(), ec.message()));
    created_ = true;
  }
  fd_ = ::open(dir_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd_ < 0) throw_io_error("open the run directory", dir_);
  int rc;
  while ((rc = flock(fd_, LOCK_EX | LOCK_NB)) != 0 && errno == EINTR) {
  }
  if (rc != 0) {
    const int err = errno;
    if (err == EWOULDBLOCK) {
      const std::string holder = lock_holder(fd_);
      ::close(fd_);
      fd_ = -1;
      throw ConfigError(
          fmt::format("{} is in use by {}: one process at a time may run, resume or analyse a run "
                      "directory; nothing was changed",
                      dir_.string(), holder));
    }
    // A file system without locks (some network mounts): run, but say it.
    std::fprintf(stderr, "warning: cannot lock %s (%s): make sure no other process uses it\n",
                 dir_.c_str(), std::strerror(err));
  }
}

RunDirectory::~RunDirectory() {
  tee_.reset();
  hdf5_log_.reset();
  if (hdf5_log_file_ != nullptr) std::fclose(hdf5_log_file_);
  if (created_) {
    std::error_code ec;
    if (fs::is_empty(dir_, ec) && !ec) fs::remove(dir_, ec);
  }
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

bool RunDirectory::moved() const {
  struct stat held {
  }, named{};
  if (fd_ < 0 || fstat(fd_, &held) != 0) return false;
  return stat(dir_.c_str(), &named) != 0 || named.st_dev != held.st_dev ||
         named.st_ino != held.st_ino;
}

RunState RunDirectory::state() const {
  if (moved()) {
    // Asked of the locked directory itself, wherever it is now.
    const auto has = [&](const char* name) { return faccessat(fd_, name, F_OK, 0) == 0; };
    if (has("summary.json")) return RunState::finished;
    if (has("checkpoint.bin")) return RunState::interrupted;
    return RunState::started;
  }
  std::error_code ec;
  if (fs::exists(file("summary.json"), ec)) return RunState::finished;
  if (fs::exists(file("checkpoint.bin"), ec)) return RunState::interrupted;
  return run_files_present().empty() ? RunState::empty : RunState::started;
}

std::string RunDirectory::run_files_present() const {
  std::string list;
  std::error_code ec;
  for (const auto& name : run_file_names())
    for (const auto& f : {name, name + ".tmp"})
      if (fs::exists(file(f), ec)) list += (list.empty() ? "" : ", ") + f;
  return list;
}

void RunDirectory::remove_run_files(bool keep_log) {
  for (const auto& name : run_file_names()) {
    for (const auto& f : {name, name + ".tmp"}) {
      if (keep_log && f == kLog) continue;
      std::error_code ec;
      fs::remove_all(file(f), ec);  // reanalysis/ and earlier/ are folders
      if (ec) throw IoError(fmt::format("cannot remove {}: {}", file(f).string(), ec.message()));
    }
  }
}

void RunDirectory::remove_partial_files() {
  for (const auto& name : run_file_names()) {
    std::error_code ec;
    fs::remove(file(name + ".tmp"), ec);
    fs::remove(file("reanalysis") / (name + ".tmp"), ec);
  }
}

void RunDirectory::start_log(const std::string& header) {
  if (tee_) return;
  const int log_fd = ::open(file(kLog).c_str(), O_RDWR | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) throw_io_error("open", file(kLog));
  // A log cut off mid-line (a full disk, a kill) gets its line ended first.
  char last = '\n';
  const off_t size = lseek(log_fd, 0, SEEK_END);
  if (size > 0 && pread(log_fd, &last, 1, size - 1) != 1) last = '\n';
  const std::string line =
      fmt::format("{}=== {} on {}, pid {}, {}: {}\n", last == '\n' ? "" : "\n", iso8601_utc_now(),
                  host_name(), static_cast<long>(getpid()), version_line(), header);
  write_all(log_fd, line.data(), line.size());
  hdf5_log_file_ = fdopen(fcntl(log_fd, F_DUPFD_CLOEXEC, 3), "a");
  if (hdf5_log_file_ != nullptr) hdf5_log_ = std::make_unique<Hdf5ErrorLog>(hdf5_log_file_);
  tee_ = std::make_unique<OutputTee>(log_fd);
}

bool RunDirectory::terminal() const {
  return tee_ ? tee_->terminal() : isatty(STDERR_FILENO) != 0;
}

void RunDirectory::log_only(std::string_view text) {
  if (tee_) tee_->log_only(text);
}

void RunDirectory::with_hdf5_reasons(const std::function<void()>& f) const {
  const long before = hdf5_log_ ? hdf5_log_->errors() : 0;
  try {
    f();
  } catch (const IoError&) {
    throw;
  } catch (const ConfigError&) {
    throw;
  } catch (const std::runtime_error& e) {
    if (!hdf5_log_ || hdf5_log_->errors() == before) throw;
    const std::string& reason = hdf5_log_->last_os_reason();
    throw IoError(fmt::format("{}: {}", e.what(),
                              reason.empty() ? "HDF5 failed (see the stack in run.log)" : reason));
  }
}

}  // namespace sheardiff
