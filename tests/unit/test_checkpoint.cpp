// Kill-and-resume: a run killed at a random moment (SIGKILL) or stopped by SIGTERM and resumed
// from its checkpoint ends in the same state, to the bit, as a run that was never stopped.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <regex>
#include <sstream>
#include <thread>

#include "scratch_dir.hpp"
#include "sheardiff/core/archive.hpp"
#include "sheardiff/core/text.hpp"
#include "sheardiff/io/checkpoint_file.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/io/run_directory.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/version.hpp"

namespace sheardiff {
namespace {

namespace fs = std::filesystem;

fs::path binary() {
  return fs::canonical("/proc/self/exe").parent_path().parent_path() / "sheardiff";
}

// A small pressure-cell run with every observer on, long enough to be killed in the middle.
fs::path write_config(const fs::path& dir, const std::string& scene = "pressure_shear",
                      bool diffusion = true) {
  fs::create_directories(dir);
  const auto file = dir / "run.toml";
  std::ofstream(file) << "[scene]\ntype = \"" << scene << "\"\n"
                      << "[analysis]\ndiffusion = " << (diffusion ? "true" : "false") << "\n"
                      << R"(msd_window_lo = 0.1
msd_window_hi = 0.3
reference_times = 20
vacf_max_lag = 0.2
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
[output]
frame_strain = 0.02
checkpoint_strain = 0.1
contacts = true
)";
  return file;
}

// `sheardiff run CFG ARGS...`, its stderr into `err` if given.
pid_t spawn_run(const fs::path& cfg, const std::vector<std::string>& extra,
                const fs::path& err = "/dev/null") {
  std::vector<std::string> args = {binary().string(), "run", cfg.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    freopen("/dev/null", "w", stdout);
    freopen(err.c_str(), "w", stderr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}
pid_t spawn(const fs::path& cfg, const fs::path& out) {
  return spawn_run(cfg, {"--out", out.string()});
}
pid_t spawn_resume(const fs::path& cfg, const fs::path& dir,
                   const std::vector<std::string>& extra = {}, const fs::path& err = "/dev/null") {
  std::vector<std::string> args = {"--resume", dir.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return spawn_run(cfg, args, err);
}

// Waits until the run writing DIR has replaced its checkpoint.bin N times (each is a new file,
// renamed over the last); false if that has not happened within a minute.
bool wait_for_checkpoints(const fs::path& dir, int n) {
  const std::string file = (dir / "checkpoint.bin").string();
  struct stat last {};
  int seen = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (seen < n && std::chrono::steady_clock::now() < end) {
    struct stat st {};
    if (::stat(file.c_str(), &st) == 0 &&
        (st.st_ino != last.st_ino || st.st_mtim.tv_sec != last.st_mtim.tv_sec ||
         st.st_mtim.tv_nsec != last.st_mtim.tv_nsec)) {
      ++seen;
      last = st;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  return seen >= n;
}

int wait_exit(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// with_counters: the checkpoint held the solver's work counters; with_sticking: and the sticking
// re-solve counters (a later addition at its end).
void expect_same_final_state(const fs::path& a, const fs::path& b, bool with_counters = true,
                             bool with_sticking = true) {
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
  // The whole summary but the clock (issue 16: the solver's work counters, factorisations,
  // restarted from 0 at a resume) and the dates (two runs).
  for (const char* clock : {"wall_seconds", "ms_per_step", "started", "finished"})
    sa.erase(clock), sb.erase(clock);
  if (!with_counters) sa.erase("factorisations"), sb.erase("factorisations");
  if (!with_counters || !with_sticking)
    sa.erase("sticking_resolves_per_step"), sb.erase("sticking_resolves_per_step");
  EXPECT_EQ(sa, sb);
  EXPECT_FALSE(fs::exists(b / "checkpoint.bin")) << "a finished run keeps no checkpoint";
}

TEST(Checkpoint, SigkillAtRandomMomentThenResumeIsBitIdentical) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  ASSERT_EQ(wait_exit(spawn(cfg, root / "whole")), 0);

  std::mt19937 rng(std::random_device{}());
  const pid_t pid = spawn(cfg, root / "killed");
  // Kill at a random moment after the first checkpoint exists (before it, there is nothing to
  // resume and a user would simply start again) and before the run ends, on a machine of any
  // speed: after 1 to 15 of the 20 checkpoint writes of a whole run, then up to 5 ms on (a few
  // steps), so that the kill may land in any part of a step or of a checkpoint's write.
  const int writes = std::uniform_int_distribution<int>(1, 15)(rng);
  const bool before_end = wait_for_checkpoints(root / "killed", writes);
  std::this_thread::sleep_for(
      std::chrono::microseconds(std::uniform_int_distribution<int>(0, 5000)(rng)));
  kill(pid, SIGKILL);
  ASSERT_TRUE(before_end) << "the run ended before its checkpoint write " << writes;
  ASSERT_EQ(wait_exit(pid), 128 + SIGKILL) << "after checkpoint write " << writes;
  ASSERT_TRUE(fs::exists(root / "killed" / "checkpoint.bin"));
  EXPECT_FALSE(fs::exists(root / "killed" / "summary.json"))
      << "a killed run must not look finished";

  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "killed")), 0);
  expect_same_final_state(root / "whole", root / "killed");
}

TEST(Checkpoint, SigtermWritesCheckpointAndExitsCleanly) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  ASSERT_EQ(wait_exit(spawn(cfg, root / "whole")), 0);
  const pid_t pid = spawn(cfg, root / "stopped");
  const bool before_end = wait_for_checkpoints(root / "stopped", 3);
  kill(pid, SIGTERM);
  ASSERT_TRUE(before_end) << "the run ended before its third checkpoint write";
  ASSERT_EQ(wait_exit(pid), 128 + SIGTERM);
  ASSERT_TRUE(fs::exists(root / "stopped" / "checkpoint.bin"));
  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "stopped")), 0);
  expect_same_final_state(root / "whole", root / "stopped");
}

TEST(Checkpoint, ResumeRefusesAnotherConfiguration) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  const pid_t pid = spawn(cfg, root / "run");
  const bool before_end = wait_for_checkpoints(root / "run", 1);
  kill(pid, SIGKILL);
  ASSERT_TRUE(before_end) << "the run ended before its first checkpoint";
  ASSERT_EQ(wait_exit(pid), 128 + SIGKILL);
  // Resuming with a different J is a configuration error (exit 2), not a silent mix.
  EXPECT_EQ(wait_exit(spawn_resume(cfg, root / "run", {"--set", "flow.J=0.1"})), 2);
}

std::vector<char> bytes_of(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}
void write_bytes(const fs::path& f, const std::vector<char>& b) {
  std::ofstream(f, std::ios::binary).write(b.data(), static_cast<std::streamsize>(b.size()));
}
std::string text_of(const fs::path& f) {
  std::ifstream in(f);
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

// DIR stopped by SIGTERM at (or just after) its first periodic checkpoint.
void make_interrupted_run(const fs::path& cfg, const fs::path& dir) {
  const pid_t pid = spawn(cfg, dir);
  const bool before_end = wait_for_checkpoints(dir, 1);
  kill(pid, SIGTERM);
  ASSERT_TRUE(before_end) << "the run ended before its first checkpoint";
  ASSERT_EQ(wait_exit(pid), 128 + SIGTERM);
  ASSERT_TRUE(fs::exists(dir / "checkpoint.bin"));
}

// A finished run extended to a larger strain (--resume with a larger run.strain) is, to the
// bit, the run that was started with that strain: the end is only tested, never anticipated.
// What it had written when it finished is kept in earlier/end_strain=S/.
TEST(Checkpoint, ExtendedRunIsTheLongerRunToTheBit) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  ASSERT_EQ(wait_exit(spawn(cfg, root / "direct")), 0);
  ASSERT_EQ(
      wait_exit(spawn_run(cfg, {"--out", (root / "ext").string(), "--set", "run.strain=1.2"})), 0);
  ASSERT_TRUE(fs::exists(root / "ext" / "final_state.bin")) << "a finished run keeps its end";
  nlohmann::json first;
  std::ifstream(root / "ext" / "summary.json") >> first;
  const fs::path err = root / "err.txt";
  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "ext", {}, err)), 0) << text_of(err);
  EXPECT_NE(text_of(err).find("extended: the finished run goes on from strain"), std::string::npos)
      << text_of(err);
  expect_same_final_state(root / "direct", root / "ext");
  EXPECT_EQ(text_of(root / "ext" / "config.toml"), text_of(root / "direct" / "config.toml"));
  // The earlier results, unchanged.
  std::vector<fs::path> kept;
  for (const auto& e : fs::directory_iterator(root / "ext" / "earlier")) kept.push_back(e.path());
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].filename().string().rfind("end_strain=1.2", 0), 0u) << kept[0];
  nlohmann::json earlier;
  std::ifstream(kept[0] / "summary.json") >> earlier;
  EXPECT_EQ(earlier, first);
  EXPECT_TRUE(fs::exists(kept[0] / "analysis.h5"));
  EXPECT_NE(text_of(kept[0] / "config.toml").find("strain = 1.2"), std::string::npos);
}

// Only the end may change: another J is refused naming the key, a shorter end and an end the
// run has passed are refused, a run finished without its final state cannot be extended; each
// refusal (exit 2) leaves the directory as it was. An interrupted run may be given a further end.
TEST(Checkpoint, ExtensionOnlyMovesTheEnd) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  const fs::path dir = root / "run", err = root / "err.txt";
  ASSERT_EQ(wait_exit(spawn(cfg, dir)), 0);
  const auto summary = bytes_of(dir / "summary.json");
  const auto config = bytes_of(dir / "config.toml");
  const auto expect_refused = [&](const std::vector<std::string>& set, const std::string& says) {
    EXPECT_EQ(wait_exit(spawn_resume(cfg, dir, set, err)), 2) << says;
    EXPECT_NE(text_of(err).find(says), std::string::npos) << text_of(err);
    EXPECT_EQ(bytes_of(dir / "summary.json"), summary);
    EXPECT_EQ(bytes_of(dir / "config.toml"), config);
    EXPECT_TRUE(fs::exists(dir / "analysis.h5"));
    EXPECT_FALSE(fs::exists(dir / "earlier"));
    EXPECT_FALSE(fs::exists(dir / "checkpoint.bin"));
  };
  expect_refused({"--set", "flow.J=0.1", "--set", "run.strain=3"}, "flow.J: 0.03 -> 0.1");
  expect_refused({"--set", "run.strain=1.5"}, "run.strain: 2.0 -> 1.5");
  // The pressure cell stops at steady + measure_strain when that comes first.
  expect_refused({"--set", "steady.measure_strain=0.5", "--set", "run.strain=3"},
                 "the run would stop where it is");
  // The trajectory it would continue is checked before anything is moved.
  fs::rename(dir / "trajectory.h5", root / "trajectory.h5");
  expect_refused({"--set", "run.strain=3"}, "is missing or holds fewer frames");
  fs::rename(root / "trajectory.h5", dir / "trajectory.h5");
  fs::remove(dir / "final_state.bin");
  expect_refused({"--set", "run.strain=3"}, "without keeping its final state");
  // An interrupted run goes on to its new end, which config.toml then holds.
  make_interrupted_run(cfg, root / "int");
  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "int", {"--set", "run.strain=2.5"}, err)), 0)
      << text_of(err);
  EXPECT_NE(text_of(err).find("extended: the run goes on"), std::string::npos) << text_of(err);
  nlohmann::json js;
  std::ifstream(root / "int" / "summary.json") >> js;
  EXPECT_NEAR(js["strain"].get<double>(), 2.5, 0.01);
  EXPECT_NE(text_of(root / "int" / "config.toml").find("strain = 2.5"), std::string::npos);
}

// A finished run whose summary.json was deleted, or one whose checkpoint.bin was, looked like a
// start killed before its first checkpoint: --resume deleted its analysis and rewrote its whole
// trajectory from strain 0. It must be refused (exit 2) with every file left as it was.
TEST(Checkpoint, ResumeNeverRestartsARunThatGotPastItsFirstCheckpoint) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  const fs::path dir = root / "run";
  ASSERT_EQ(wait_exit(spawn(cfg, dir)), 0);
  fs::remove(dir / "summary.json");
  const auto trajectory = bytes_of(dir / "trajectory.h5");
  const auto analysis = bytes_of(dir / "analysis.h5");
  const fs::path err = root / "err.txt";
  EXPECT_EQ(wait_exit(spawn_resume(cfg, dir, {}, err)), 2);
  const std::string message = text_of(err);
  EXPECT_NE(message.find("neither checkpoint.bin nor summary.json"), std::string::npos) << message;
  EXPECT_NE(message.find("analysis.h5"), std::string::npos) << message;
  EXPECT_NE(message.find("--overwrite"), std::string::npos) << message;
  EXPECT_EQ(bytes_of(dir / "trajectory.h5"), trajectory);
  EXPECT_EQ(bytes_of(dir / "analysis.h5"), analysis);
  // Without the analysis either, its frames past the first checkpoint (strain 0.1 of 2) say it.
  fs::remove(dir / "analysis.h5");
  EXPECT_EQ(wait_exit(spawn_resume(cfg, dir, {}, err)), 2);
  EXPECT_NE(text_of(err).find("past the first checkpoint"), std::string::npos) << text_of(err);
  EXPECT_EQ(bytes_of(dir / "trajectory.h5"), trajectory);
  // A sweep asks the same question of a point directory before it starts one afresh.
  RunDirectory held(dir, false);
  EXPECT_NE(restart_would_lose(held, load_config(cfg)), "");
}

// A resumed run whose config.toml had been deleted finished without it, and `analyse` then
// failed: the resume writes it again from the checkpoint's (checked) configuration.
TEST(Checkpoint, ResumeWritesADeletedConfigAgain) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  const fs::path dir = root / "run";
  make_interrupted_run(cfg, dir);
  const std::string config = text_of(dir / "config.toml");
  fs::remove(dir / "config.toml");
  const fs::path err = root / "err.txt";
  ASSERT_EQ(wait_exit(spawn_resume(cfg, dir, {}, err)), 0) << text_of(err);
  EXPECT_NE(text_of(err).find("config.toml was missing"), std::string::npos) << text_of(err);
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
  EXPECT_EQ(text_of(dir / "config.toml"), config);
}

// Issue 35, case 11: a checkpoint.bin that is a directory gave "basic_filebuf::underflow error
// ... Is a directory" naming no file; a run whose directory was renamed under it said "No
// checkpoint was written yet" though one existed.
TEST(Checkpoint, MessagesNameTheFileAndWhereTheRunWent) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  const fs::path err = root / "err.txt";
  make_interrupted_run(cfg, root / "dir_checkpoint");
  fs::remove(root / "dir_checkpoint" / "checkpoint.bin");
  fs::create_directory(root / "dir_checkpoint" / "checkpoint.bin");
  EXPECT_EQ(wait_exit(spawn_resume(cfg, root / "dir_checkpoint", {}, err)), 2);
  EXPECT_NE(text_of(err).find((root / "dir_checkpoint" / "checkpoint.bin").string() +
                              " is corrupt: it is not a regular file"),
            std::string::npos)
      << text_of(err);
  EXPECT_TRUE(fs::is_directory(root / "dir_checkpoint" / "checkpoint.bin"));

  // Renamed once its first checkpoint exists: the next checkpoint cannot be written there.
  const fs::path dir = root / "run", moved = root / "moved";
  const pid_t pid = spawn_run(cfg, {"--out", dir.string()}, err);
  ASSERT_TRUE(wait_for_checkpoints(dir, 1)) << "the run ended before its first checkpoint";
  fs::rename(dir, moved);
  EXPECT_EQ(wait_exit(pid), 1);
  const std::string m = text_of(err);
  EXPECT_NE(m.find(dir.string() + " was moved or removed while the run ran"), std::string::npos)
      << m;
  EXPECT_NE(m.find("its checkpoint.bin went with it"), std::string::npos) << m;
  EXPECT_EQ(m.find("No checkpoint was written yet"), std::string::npos) << m;
  // And it continues where it is now.
  EXPECT_EQ(wait_exit(spawn_resume(cfg, moved, {}, err)), 0) << text_of(err);
  EXPECT_TRUE(fs::exists(moved / "summary.json"));
}

// The trajectory's image counts, every frame.
std::vector<int> image_counts(const fs::path& traj) {
  const hid_t f = H5Fopen(traj.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, "/particles/suspension/image/value", H5P_DEFAULT);
  const hid_t sp = H5Dget_space(d);
  std::vector<int> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(sp)));
  H5Dread(d, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(sp);
  H5Dclose(d);
  H5Fclose(f);
  return v;
}

// Issue 34: the image counts are state (the Lees-Edwards shift gained since each crossing is
// not in the positions), kept in the checkpoint: a simple-shear run stopped late and resumed
// writes the images of the run never stopped.
TEST(Checkpoint, ImageCountsSurviveAResume) {
  const ScratchDir root;
  const fs::path cfg = write_config(root, "simple_shear");
  ASSERT_EQ(wait_exit(spawn(cfg, root / "whole")), 0);
  const pid_t pid = spawn(cfg, root / "stopped");
  // Late in the run, where discs have crossed, on a machine of any speed or load: after 14 of
  // the 20 checkpoint writes of a whole run (at strain 1.4 of 2 or later).
  const bool late = wait_for_checkpoints(root / "stopped", 14);
  kill(pid, SIGTERM);
  ASSERT_TRUE(late) << "the run ended before its 14th checkpoint";
  ASSERT_EQ(wait_exit(pid), 128 + SIGTERM);
  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "stopped")), 0);
  const auto a = image_counts(root / "whole" / "trajectory.h5");
  EXPECT_EQ(a, image_counts(root / "stopped" / "trajectory.h5"));
  EXPECT_NE(std::count(a.begin(), a.end(), 0), static_cast<long>(a.size())) << "no crossing";
}

// Issue 35, case 3: channel runs resumed 1e-13 d off in the first frame after the checkpoint and
// 2e-6 d later: the fluid layer's sparsity pattern was rebuilt from the positions at the
// checkpoint instead of those at the last neighbour rebuild, so CHOLMOD ordered another matrix.
// Layout 5 keeps those heights: a channel run killed and resumed ends bit-identical.
TEST(Checkpoint, ChannelResumeIsBitIdentical) {
  const ScratchDir root;
  const fs::path cfg = root / "channel.toml";
  // Case D of configs/channel (86 discs, H = 40.4 a), whose resumes differed from strain 20 on.
  std::ofstream(cfg) << R"([scene]
type = "channel"
[particles]
size_ratio = 1.0
[channel]
phi = 0.4
h_over_a = 40.4
wall_discs = 7
coupling = "two_way"
sample_interval = 50.0
steady_window = 6000.0
[contact]
mu = 0.0
[repulsion]
F0 = 9.42477796076938
lambda = 0.0005
[run]
strain = 120.0
seed = 1
[analysis]
diffusion = false
[output]
frame_strain = 10.0
checkpoint_strain = 20.0
)";
  ASSERT_EQ(wait_exit(spawn(cfg, root / "whole")), 0);
  // Killed once its first checkpoint (strain 20) exists: resumed from there.
  const pid_t pid = spawn(cfg, root / "stopped");
  const bool before_end = wait_for_checkpoints(root / "stopped", 1);
  kill(pid, SIGKILL);
  ASSERT_TRUE(before_end) << "the run ended before its first checkpoint";
  ASSERT_EQ(wait_exit(pid), 128 + SIGKILL);
  ASSERT_TRUE(fs::exists(root / "stopped" / "checkpoint.bin"));
  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "stopped")), 0);
  const long n = count_h5md_frames(root / "whole" / "trajectory.h5");
  ASSERT_EQ(count_h5md_frames(root / "stopped" / "trajectory.h5"), n);
  for (long f = 0; f < n; ++f) {
    const H5mdFrame a = read_h5md_frame(root / "whole" / "trajectory.h5", f);
    const H5mdFrame b = read_h5md_frame(root / "stopped" / "trajectory.h5", f);
    ASSERT_EQ(a.position.size(), b.position.size());
    for (std::size_t i = 0; i < a.position.size(); ++i)
      ASSERT_EQ(a.position[i], b.position[i]) << "frame " << f << ", particle " << i;
  }
  nlohmann::json sa, sb;
  std::ifstream(root / "whole" / "summary.json") >> sa;
  std::ifstream(root / "stopped" / "summary.json") >> sb;
  for (const char* clock : {"wall_seconds", "ms_per_step", "started", "finished"})
    sa.erase(clock), sb.erase(clock);
  EXPECT_EQ(sa, sb);
}

// Issue 16: a flipped mantissa byte resumed to exit 0 with other results, a flipped exponent
// was reported as "top wall escaped" (exit 4) and the checkpoint overwritten, a corrupt length
// ended in std::bad_alloc without the file's name. Each must be named as corrupt (exit 2) and
// the file left as it is.
TEST(Checkpoint, CorruptCheckpointIsNamedNeverResumedNeverOverwritten) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  make_interrupted_run(cfg, root / "run");
  const std::vector<char> pristine = bytes_of(root / "run" / "checkpoint.bin");
  // The first particle position follows the "dynamics" tag and the vector's length.
  const std::string tag = "dynamics";
  const auto at = std::search(pristine.begin(), pristine.end(), tag.begin(), tag.end());
  ASSERT_NE(at, pristine.end());
  const std::size_t x0 = static_cast<std::size_t>(at - pristine.begin()) + tag.size() + 8;
  struct Case {
    const char* name;
    std::size_t offset;
    char flip;
  };
  for (const Case& c : {Case{"mantissa", x0 + 2, 0x01}, Case{"exponent", x0 + 7, 0x10},
                        Case{"length", 8 + 22, 0x01}}) {
    SCOPED_TRACE(c.name);
    const fs::path dir = root / c.name;
    fs::copy(root / "run", dir, fs::copy_options::recursive);
    std::vector<char> bad = pristine;
    bad[c.offset] = static_cast<char>(bad[c.offset] ^ c.flip);
    write_bytes(dir / "checkpoint.bin", bad);
    EXPECT_EQ(wait_exit(spawn_resume(cfg, dir, {}, root / "err.txt")), 2);
    const std::string err = text_of(root / "err.txt");
    EXPECT_NE(err.find((dir / "checkpoint.bin").string() + " is corrupt"), std::string::npos)
        << err;
    EXPECT_EQ(bytes_of(dir / "checkpoint.bin"), bad) << "the checkpoint was changed";
    EXPECT_FALSE(fs::exists(dir / "summary.json"));
    EXPECT_FALSE(fs::exists(dir / "diagnostic.txt"));
  }
}

// A corrupt length field inside the state is bounded by what is left of the file.
TEST(Checkpoint, ArchiveLengthsAreBoundedByTheFile) {
  Archive w = Archive::writer();
  std::vector<double> v{1.0, 2.0, 3.0};
  w.io(v);
  std::vector<char> bytes = w.bytes();
  const std::uint64_t huge = std::uint64_t{1} << 50;
  std::memcpy(bytes.data(), &huge, sizeof huge);
  Archive r = Archive::reader(bytes);
  std::vector<double> back;
  try {
    r.io(back);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("length field"), std::string::npos) << e.what();
  }
}

// Checkpoints of sheardiff before issue 16 (version 2: no header, no checksum, no solver
// counters) still resume, with a warning, to the same results: those of a simple-shear run
// without the diffusion analysis, whose state layout has not changed since (a pressure cell's
// has, and so has the diffusion analysis's: the next tests).
TEST(Checkpoint, VersionTwoCheckpointStillResumes) {
  const ScratchDir root;
  const fs::path cfg = write_config(root, "simple_shear", /*diffusion=*/false);
  ASSERT_EQ(wait_exit(spawn(cfg, root / "whole")), 0);
  make_interrupted_run(cfg, root / "old");
  const std::vector<char> v3 = bytes_of(root / "old" / "checkpoint.bin");
  // Version 3 payloads end with the counters, since issue 17 the start time, and since issue 13
  // the sticking re-solve counters (4 longs).
  const std::size_t header = 8 + 22 + 8 + 4,
                    counters = 4 * sizeof(std::size_t) + 8 + 4 * sizeof(long);
  ASSERT_GT(v3.size(), header + counters);
  // Layout 5 added the image counts (80 discs) as their own section, which version 2 lacks.
  const std::string images = "images";
  const auto at = std::search(v3.begin(), v3.end(), images.begin(), images.end());
  ASSERT_NE(at, v3.end());
  std::vector<char> v4(v3.begin(), at - 8);
  v4.insert(v4.end(), at + static_cast<long>(images.size() + 8 + 80 * 8), v3.end());
  std::vector<char> v2(8);
  const std::uint64_t magic_length = 22;
  std::memcpy(v2.data(), &magic_length, 8);
  const std::string magic = "sheardiff-checkpoint-2";
  v2.insert(v2.end(), magic.begin(), magic.end());
  v2.insert(v2.end(), v4.begin() + header, v4.end() - counters);
  write_bytes(root / "old" / "checkpoint.bin", v2);
  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "old", {}, root / "err.txt")), 0);
  EXPECT_NE(text_of(root / "err.txt").find("has no checksum"), std::string::npos);
  expect_same_final_state(root / "whole", root / "old", /*with_counters=*/false);
}

// A pressure-cell checkpoint of layout 3 (before the gap profiles became their own observer)
// cannot be placed in today's state: refused before anything is read, with that reason and the
// way out (the sheardiff that started it), exit 2, the file left as it was.
TEST(Checkpoint, OlderPressureCellLayoutIsRefusedWithItsReason) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  make_interrupted_run(cfg, root / "old");
  std::vector<char> bytes = bytes_of(root / "old" / "checkpoint.bin");
  const std::string now = "sheardiff-checkpoint-9", before = "sheardiff-checkpoint-3";
  ASSERT_EQ(std::string(bytes.data() + 8, now.size()), now);
  std::memcpy(bytes.data() + 8, before.data(), before.size());  // the CRC covers the payload only
  write_bytes(root / "old" / "checkpoint.bin", bytes);
  EXPECT_EQ(wait_exit(spawn_resume(cfg, root / "old", {}, root / "err.txt")), 2);
  const std::string err = text_of(root / "err.txt");
  EXPECT_NE(err.find("earlier sheardiff (checkpoint layout 3)"), std::string::npos) << err;
  EXPECT_NE(err.find("run.log"), std::string::npos) << err;
  EXPECT_EQ(bytes_of(root / "old" / "checkpoint.bin"), bytes);
}

// A checkpoint of layout 5 kept the measured window's frames for the diffusion analysis; this
// version accumulates it while running, so such a state cannot be continued: refused with that
// reason and the way out, exit 2, the file left as it was.
TEST(Checkpoint, FrameKeepingDiffusionLayoutIsRefusedWithItsReason) {
  const ScratchDir root;
  const fs::path cfg = write_config(root, "simple_shear");
  make_interrupted_run(cfg, root / "old");
  std::vector<char> bytes = bytes_of(root / "old" / "checkpoint.bin");
  const std::string now = "sheardiff-checkpoint-9", before = "sheardiff-checkpoint-5";
  ASSERT_EQ(std::string(bytes.data() + 8, now.size()), now);
  std::memcpy(bytes.data() + 8, before.data(), before.size());
  write_bytes(root / "old" / "checkpoint.bin", bytes);
  EXPECT_EQ(wait_exit(spawn_resume(cfg, root / "old", {}, root / "err.txt")), 2);
  const std::string err = text_of(root / "err.txt");
  EXPECT_NE(err.find("(checkpoint layout 5), which kept the measured window's frames"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("--overwrite"), std::string::npos) << err;
  EXPECT_EQ(bytes_of(root / "old" / "checkpoint.bin"), bytes);
}

// Issue 17: the summary says when the run started, its first start for a resumed run (kept in
// the checkpoint), and when it finished, in ISO 8601 UTC, with the version, host and seed.
TEST(Checkpoint, ResumedRunKeepsItsStartTime) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  make_interrupted_run(cfg, root / "run");
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  const std::string resumed_at = iso8601_utc_now();
  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "run")), 0);
  nlohmann::json js;
  std::ifstream(root / "run" / "summary.json") >> js;
  const std::regex iso(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)");
  ASSERT_TRUE(js["started"].is_string()) << js.dump(2);
  EXPECT_TRUE(std::regex_match(js["started"].get<std::string>(), iso)) << js["started"];
  EXPECT_TRUE(std::regex_match(js["finished"].get<std::string>(), iso)) << js["finished"];
  EXPECT_LT(js["started"].get<std::string>(), resumed_at) << "the start of the resume, not the run";
  EXPECT_GE(js["finished"].get<std::string>(), resumed_at);
  EXPECT_EQ(js["seed"], 4);
  EXPECT_EQ(js["version"], version());
  EXPECT_EQ(js["git_hash"], git_hash());
  EXPECT_EQ(js["host"], host_name());
}

// A checkpoint of the sheardiff before issue 17 holds its configuration with 17-digit floats
// (phi_init = 0.71999999999999997) and no start time: it resumes to the same results, the
// start unknown (null), rather than being refused as another configuration.
TEST(Checkpoint, CheckpointWithOldFloatTextStillResumes) {
  const ScratchDir root;
  const fs::path cfg = write_config(root);
  ASSERT_EQ(wait_exit(spawn(cfg, root / "whole")), 0);
  make_interrupted_run(cfg, root / "old");
  std::vector<char> payload = read_checkpoint_file(root / "old" / "checkpoint.bin").bytes;
  // The payload starts with the resolved configuration (a length and the text).
  Archive a = Archive::reader(payload);
  std::string text;
  a.io(text);
  const std::size_t rest = 8 + text.size();
  std::istringstream lines(text);
  std::string old_text;
  int rewritten = 0;
  for (std::string line; std::getline(lines, line);) {
    const auto eq = line.find(" = ");
    if (eq != std::string::npos && line.find('.', eq) != std::string::npos && line[eq + 3] != '"') {
      const double x = std::strtod(line.c_str() + eq + 3, nullptr);
      const std::string long_form = fmt::format("{:.17g}", x);
      rewritten += long_form != line.substr(eq + 3);
      line = line.substr(0, eq + 3) + long_form;
    }
    old_text += line + "\n";
  }
  ASSERT_GT(rewritten, 5) << old_text;
  ASSERT_NE(old_text.find("phi_init = 0.71999999999999997"), std::string::npos) << old_text;
  Archive w = Archive::writer();
  w.io(old_text);
  std::vector<char> old_payload = w.bytes();
  // Without the start time (8 bytes) and the sticking re-solve counters after it (4 x 8).
  old_payload.insert(old_payload.end(), payload.begin() + static_cast<long>(rest),
                     payload.end() - 40);
  const std::vector<char> file = checkpoint_file_bytes(old_payload);
  write_bytes(root / "old" / "checkpoint.bin", file);
  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "old", {}, root / "err.txt")), 0)
      << text_of(root / "err.txt");
  expect_same_final_state(root / "whole", root / "old", true, false);
  nlohmann::json js;
  std::ifstream(root / "old" / "summary.json") >> js;
  EXPECT_TRUE(js["started"].is_null()) << js["started"];
}

// Issue 16: SIGTERM while the initial packing was built killed the process (143) with no
// checkpoint. It now waits for the set-up and checkpoints at step 0.
TEST(Checkpoint, SigtermDuringSetUpWritesCheckpoint) {
  const ScratchDir root;
  const fs::path cfg = root / "slow_setup.toml";
  // Compressing 1000 discs to phi = 0.8 takes seconds; the run itself 3 steps.
  std::ofstream(cfg) << R"([scene]
type = "simple_shear"
[particles]
N = 1000
phi_init = 0.8
[run]
max_steps = 3
[output]
frame_strain = 0.01
[analysis]
diffusion = false
)";
  const pid_t pid = spawn(cfg, root / "run");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  kill(pid, SIGTERM);
  ASSERT_EQ(wait_exit(pid), 128 + SIGTERM);
  ASSERT_TRUE(fs::exists(root / "run" / "checkpoint.bin"));
  ASSERT_EQ(wait_exit(spawn_resume(cfg, root / "run")), 0);
  nlohmann::json js;
  std::ifstream(root / "run" / "summary.json") >> js;
  EXPECT_EQ(js["steps"], 3);
}

}  // namespace
}  // namespace sheardiff
