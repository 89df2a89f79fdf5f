// Kill-and-resume: a run killed at a random moment (SIGKILL) or stopped by SIGTERM and resumed
// from its checkpoint ends in the same state, to the bit, as a run that was never stopped.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "sheardiff/io/h5md.hpp"
#include "sheardiff/simulation.hpp"

namespace sheardiff {
namespace {

namespace fs = std::filesystem;

fs::path binary() { return fs::canonical("/proc/self/exe").parent_path().parent_path() / "sheardiff"; }

// A small pressure-cell run with every observer on, long enough to be killed in the middle.
fs::path write_config(const fs::path& dir) {
  fs::create_directories(dir);
  const auto file = dir / "run.toml";
  std::ofstream(file) << R"([scene]
type = "pressure_shear"
[particles]
N = 80
phi_init = 0.72
[flow]
J = 3e-2
[contact]
ktilde = 1e3
[run]
strain = 2.0
seed = 4
[steady]
window = 0.5
[analysis]
msd_window_lo = 0.1
msd_window_hi = 0.3
reference_times = 20
vacf_max_lag = 0.2
[output]
frame_strain = 0.02
checkpoint_strain = 0.1
contacts = true
)";
  return file;
}

pid_t spawn(const fs::path& cfg, const fs::path& out, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args = {binary().string(), "run", cfg.string(), "--out", out.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    freopen("/dev/null", "w", stdout);
    freopen("/dev/null", "w", stderr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

void expect_same_final_state(const fs::path& a, const fs::path& b) {
  const H5mdFrame fa = read_h5md_frame(a / "trajectory.h5", -1);
  const H5mdFrame fb = read_h5md_frame(b / "trajectory.h5", -1);
  EXPECT_EQ(count_h5md_frames(a / "trajectory.h5"), count_h5md_frames(b / "trajectory.h5"));
  EXPECT_EQ(fa.step, fb.step);
  EXPECT_EQ(fa.time, fb.time);  // bit-identical doubles
  ASSERT_EQ(fa.position.size(), fb.position.size());
  for (std::size_t i = 0; i < fa.position.size(); ++i) {
    ASSERT_EQ(fa.position[i], fb.position[i]) << "particle " << i;
    ASSERT_EQ(fa.velocity[i], fb.velocity[i]) << "particle " << i;
  }
  // The ragged contact datasets are cut back and continued like the others.
  for (const long frame : {0L, count_h5md_frames(a / "trajectory.h5") / 2, -1L}) {
    const ContactNetwork ca = read_h5md_contacts(a / "trajectory.h5", frame);
    const ContactNetwork cb = read_h5md_contacts(b / "trajectory.h5", frame);
    EXPECT_FALSE(ca.pairs.empty()) << "frame " << frame;
    EXPECT_EQ(ca.pairs, cb.pairs) << "frame " << frame;
    EXPECT_EQ(ca.normal_force, cb.normal_force) << "frame " << frame;
    EXPECT_EQ(ca.tangential_force, cb.tangential_force) << "frame " << frame;
    EXPECT_EQ(ca.sliding, cb.sliding) << "frame " << frame;
  }
  nlohmann::json sa, sb;
  std::ifstream(a / "summary.json") >> sa;
  std::ifstream(b / "summary.json") >> sb;
  for (const char* key : {"steps", "strain", "phi", "mu", "H", "shear_stress", "max_overlap", "D",
                          "dv", "psi", "steady_strain", "pressure_max_relative_error"})
    EXPECT_EQ(sa[key], sb[key]) << key;
  EXPECT_FALSE(fs::exists(b / "checkpoint.bin")) << "a finished run keeps no checkpoint";
}

TEST(Checkpoint, SigkillAtRandomMomentThenResumeIsBitIdentical) {
  const fs::path root = fs::temp_directory_path() / "sheardiff_test_kill";
  fs::remove_all(root);
  const fs::path cfg = write_config(root);
  ASSERT_EQ(wait_exit(spawn(cfg, root / "whole")), 0);

  std::mt19937 rng(std::random_device{}());
  const pid_t pid = spawn(cfg, root / "killed");
  // Kill at a random moment after the first checkpoint exists (before it, there is nothing to
  // resume and a user would simply start again).
  for (int k = 0; k < 2000 && !fs::exists(root / "killed" / "checkpoint.bin"); ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(0, 400)(rng)));
  kill(pid, SIGKILL);
  const int killed = wait_exit(pid);
  if (killed == 0) GTEST_SKIP() << "the run finished before the kill landed (machine too fast)";
  ASSERT_EQ(killed, 128 + SIGKILL);
  ASSERT_TRUE(fs::exists(root / "killed" / "checkpoint.bin"));
  EXPECT_FALSE(fs::exists(root / "killed" / "summary.json")) << "a killed run must not look finished";

  ASSERT_EQ(wait_exit(spawn(cfg, root / "x", {"--resume", (root / "killed").string()})), 0);
  expect_same_final_state(root / "whole", root / "killed");
  fs::remove_all(root);
}

TEST(Checkpoint, SigtermWritesCheckpointAndExitsCleanly) {
  const fs::path root = fs::temp_directory_path() / "sheardiff_test_term";
  fs::remove_all(root);
  const fs::path cfg = write_config(root);
  ASSERT_EQ(wait_exit(spawn(cfg, root / "whole")), 0);
  const pid_t pid = spawn(cfg, root / "stopped");
  for (int k = 0; k < 2000 && !fs::exists(root / "stopped" / "trajectory.h5"); ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  kill(pid, SIGTERM);
  const int code = wait_exit(pid);
  if (code == 0) GTEST_SKIP() << "the run finished before SIGTERM landed";
  ASSERT_EQ(code, 128 + SIGTERM);
  ASSERT_TRUE(fs::exists(root / "stopped" / "checkpoint.bin"));
  ASSERT_EQ(wait_exit(spawn(cfg, root / "x", {"--resume", (root / "stopped").string()})), 0);
  expect_same_final_state(root / "whole", root / "stopped");
  fs::remove_all(root);
}

TEST(Checkpoint, ResumeRefusesAnotherConfiguration) {
  const fs::path root = fs::temp_directory_path() / "sheardiff_test_other";
  fs::remove_all(root);
  const fs::path cfg = write_config(root);
  const pid_t pid = spawn(cfg, root / "run");
  for (int k = 0; k < 2000 && !fs::exists(root / "run" / "checkpoint.bin"); ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(pid, SIGKILL);
  wait_exit(pid);
  // Resuming with a different J is a configuration error (exit 2), not a silent mix.
  EXPECT_EQ(wait_exit(spawn(cfg, root / "x", {"--resume", (root / "run").string(), "--set", "flow.J=0.1"})), 2);
  fs::remove_all(root);
}

}  // namespace
}  // namespace sheardiff
