// Run directories (issue 16): the lock, the states, the log, and atomic writes that name the
// file and the operating system's reason.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <regex>
#include <sstream>

#include "sheardiff/config.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/io_error.hpp"
#include "sheardiff/io/run_directory.hpp"

namespace sheardiff {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const auto dir =
      fs::temp_directory_path() / ("sheardiff_rundir_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  return dir;
}

std::string text_of(const fs::path& f) {
  std::ifstream in(f);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

TEST(RunDirectory, SecondHolderIsRefusedNamingTheFirst) {
  const auto dir = fresh_dir("lock");
  {
    RunDirectory first(dir, true);
    try {
      RunDirectory second(dir, true);
      FAIL() << "a second lock on one directory";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("is in use by process " + std::to_string(getpid())), std::string::npos)
          << what;
      EXPECT_NE(what.find("nothing was changed"), std::string::npos) << what;
    }
  }
  // Released with its holder; the directory this object made is removed as it stayed empty.
  EXPECT_FALSE(fs::exists(dir));
  fs::create_directories(dir);
  { RunDirectory again(dir, false); }
  EXPECT_TRUE(fs::exists(dir)) << "a directory it did not make is kept";
  fs::remove_all(dir);
  EXPECT_THROW(RunDirectory(dir, false), ConfigError);
  EXPECT_FALSE(fs::exists(dir));
}

TEST(RunDirectory, StateFollowsTheFilesOfARun) {
  const auto dir = fresh_dir("state");
  RunDirectory d(dir, true);
  std::ofstream(dir / "notes.txt") << "not a run file";
  EXPECT_EQ(d.state(), RunState::empty);
  std::ofstream(dir / "trajectory.h5") << "";
  EXPECT_EQ(d.state(), RunState::started);
  EXPECT_EQ(d.run_files_present(), "trajectory.h5");
  std::ofstream(dir / "checkpoint.bin") << "";
  EXPECT_EQ(d.state(), RunState::interrupted);
  std::ofstream(dir / "summary.json") << "{}";
  EXPECT_EQ(d.state(), RunState::finished);
  std::ofstream(dir / "summary.json.tmp") << "{";
  d.remove_partial_files();
  EXPECT_FALSE(fs::exists(dir / "summary.json.tmp"));
  d.remove_run_files(/*keep_log=*/false);
  EXPECT_EQ(d.state(), RunState::empty);
  EXPECT_TRUE(fs::exists(dir / "notes.txt")) << "only the files a run writes are removed";
  fs::remove_all(dir);
}

// The log holds what was printed, but not a terminal's live line (redrawn after '\r'): the
// run logs timestamped progress lines instead (issue 17). Its header says when (ISO 8601 UTC),
// where and which sheardiff.
TEST(RunDirectory, LogHoldsWhatWasPrintedButNotTheLiveLine) {
  const auto dir = fresh_dir("log");
  {
    RunDirectory d(dir, true);
    d.start_log("the header");
    std::fprintf(stderr, "\rstrain 0.1\rstrain 0.2\rstrain 0.3   \n");
    std::fprintf(stdout, "a result\n");
    std::cout << "another result" << std::endl;
    std::fprintf(stderr, "error: the last words");  // no newline: kept anyway
  }
  const std::string log = text_of(dir / "run.log");
  EXPECT_TRUE(std::regex_search(
      log,
      std::regex(R"(^=== \d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ on \S+, pid )" + std::to_string(getpid()) +
                 R"(, sheardiff \d+\.\d+\.\d+ \(git \S+\): the header\n)")))
      << log;
  EXPECT_EQ(log.find("strain 0."), std::string::npos) << "a live line was logged: " << log;
  EXPECT_NE(log.find("a result\n"), std::string::npos) << log;
  EXPECT_NE(log.find("another result\n"), std::string::npos) << log;
  EXPECT_NE(log.find("error: the last words"), std::string::npos) << log;
  fs::remove_all(dir);
}

// log_only: in the log, in order with what was printed, and not on the terminal (--quiet's
// result lines, the progress lines of a run on a terminal).
TEST(RunDirectory, LogOnlyTextKeepsItsPlaceAndStaysOffTheTerminal) {
  const auto dir = fresh_dir("log_only");
  fs::create_directories(dir);
  const auto screen = dir / "screen.txt";
  std::fflush(stdout);
  std::fflush(stderr);
  const int saved_out = dup(1), saved_err = dup(2);
  {
    // The "terminal" is a file, in place of fds 1 and 2 while the log runs.
    std::FILE* f = std::fopen(screen.c_str(), "w");
    dup2(fileno(f), 1);
    dup2(fileno(f), 2);
    std::fclose(f);
    RunDirectory d(dir / "run", true);
    d.start_log("order");
    EXPECT_FALSE(d.terminal());
    for (int k = 0; k < 50; ++k) {
      std::fprintf(stdout, "printed %d\n", k);
      d.log_only(fmt::format("logged {}\n", k));
    }
  }
  std::fflush(stdout);
  dup2(saved_out, 1);
  dup2(saved_err, 2);
  close(saved_out);
  close(saved_err);
  std::string want;
  for (int k = 0; k < 50; ++k) want += fmt::format("printed {}\nlogged {}\n", k, k);
  const std::string log = text_of(dir / "run" / "run.log");
  EXPECT_EQ(log.substr(log.find('\n') + 1), want);
  const std::string shown = text_of(screen);
  EXPECT_EQ(shown.find("logged"), std::string::npos) << shown;
  EXPECT_NE(shown.find("printed 49\n"), std::string::npos) << shown;
  fs::remove_all(dir);
}

// Issue 16: "cannot write X.tmp", without the reason, and the partial file left.
TEST(AtomicFile, FailureNamesTheFileAndTheReasonAndLeavesNothing) {
  const auto dir = fresh_dir("atomic");
  fs::create_directories(dir / "summary.json.tmp");  // a directory where the file goes
  try {
    write_file_atomically(dir / "summary.json", "{}\n");
    FAIL() << "no error";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find((dir / "summary.json.tmp").string()), std::string::npos) << what;
    EXPECT_NE(what.find("Is a directory"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_file_atomically(dir / "summary.json", "{}\n");
  EXPECT_EQ(text_of(dir / "summary.json"), "{}\n");
  EXPECT_FALSE(fs::exists(dir / "summary.json.tmp"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sheardiff
