// The in-run observers and `sheardiff analyse DIR` (reanalyse_run) see the same frames and give
// the same numbers, to the bit; where they would not, analyse writes beside the run's files.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "scratch_dir.hpp"
#include "sheardiff/analysis/power_law.hpp"
#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

std::string file_text(const std::filesystem::path& f);

// 60 particles in simple shear at J = 0.1 for 1.5 strains, frames (and the coarse MSD grid)
// every frame_strain, the MSD window [0.2, 0.5] and VACF lags to 0.3 strain.
Config sheared_60(double frame_strain) {
  Config c;
  c.particles.n = 60;
  c.particles.phi_init = 0.7;
  c.flow.j = 1e-1;
  c.contact.ktilde = 1e3;
  c.run.strain = 1.5;
  c.run.transient_strain = 0.3;
  c.output.frame_strain = frame_strain;
  c.analysis.coarse_strain = frame_strain;
  c.analysis.msd_window_lo = 0.2;
  c.analysis.msd_window_hi = 0.5;
  c.analysis.vacf_max_lag = 0.3;
  return c;
}

TEST(DiffusionRun, AnalyseReproducesObserverExactly) {
  Config c = sheared_60(0.01);
  // The samples are the frames, so that analyse can see them again.
  c.analysis.sample_strain = 0.01;
  c.analysis.velocity_intervals = {0.03};
  const ScratchDir dir;
  const nlohmann::json during = run_to_directory(c, dir, false);
  ASSERT_TRUE(during.contains("D"));
  ASSERT_TRUE(std::filesystem::exists(dir / "analysis.h5"));
  const Reanalysis re = reanalyse_run(dir);
  EXPECT_TRUE(re.differs.empty());
  EXPECT_EQ(re.folder, dir.path());
  const nlohmann::json& after = re.summary;
  for (const char* key :
       {"D", "D_err", "D_regression_stderr", "dv", "psi", "psi_e", "step_length", "msd_window",
        "msd_window_slope", "analysis_samples", "diffusion_consistency", "velocity_intervals",
        "dv_intervals", "psi_intervals"})
    EXPECT_EQ(during[key], after[key]) << key;
  // Physical sanity of the numbers themselves: a sheared suspension diffuses and fluctuates.
  EXPECT_GT(during["D"].get<double>(), 0.0);
  EXPECT_GT(during["dv"].get<double>(), 0.0);
  EXPECT_GT(during["psi"].get<double>(), 0.0);
  // Frames are written at the first step past each multiple of 0.01, so the one at 0.3 lies just
  // past the transient: 0.30, 0.31, ..., 1.50.
  EXPECT_EQ(during["analysis_samples"].get<long>(), 121);
  // The velocity over 0.03 strain (a seventh of Psi here: close to the instantaneous one).
  EXPECT_EQ(during["velocity_intervals"][0].get<double>(), 0.03);
  EXPECT_NEAR(during["dv_intervals"][0].get<double>(), during["dv"].get<double>(),
              0.1 * during["dv"].get<double>());
  // The x displacement relative to the imposed flow was sampled too (analyse cannot: frames
  // do not integrate it), and its MSD is positive.
  EXPECT_GT(during["D_x"].get<double>(), 0.0);

  // Another analysis setting (issue 34: analyse took no --set) analyses the same frames into
  // DIR/reanalysis/, saying so, and leaves the run's summary as it was; a key that changes the
  // run itself is refused.
  const std::string before = file_text(dir / "summary.json");
  const Reanalysis other = reanalyse_run(dir, {"analysis.msd_window_lo=0.25"});
  EXPECT_EQ(other.folder, dir / "reanalysis");
  EXPECT_EQ(file_text(dir / "summary.json"), before);
  const auto written = nlohmann::json::parse(file_text(dir / "reanalysis" / "summary.json"));
  EXPECT_EQ(written["msd_window"][0].get<double>(), 0.25);
  EXPECT_EQ(written["analysed_with"][0], "analysis.msd_window_lo=0.25");
  EXPECT_TRUE(std::filesystem::exists(dir / "reanalysis" / "analysis.h5"));
  EXPECT_THROW(reanalyse_run(dir, {"flow.J=0.2"}), ConfigError);
}

// A run sampled more finely than its frames (the default: ten samples per frame) cannot be
// re-analysed to the same numbers from its trajectory: analyse recomputes from the frames into
// DIR/reanalysis/, naming the keys that differ, and leaves the run's files alone.
TEST(DiffusionRun, FinerSamplesThanFramesAnalyseBeside) {
  const Config c = sheared_60(0.02);
  const ScratchDir dir;
  const nlohmann::json during = run_to_directory(c, dir, false);
  EXPECT_DOUBLE_EQ(during["analysis_sample_strain"].get<double>(), 0.002);
  EXPECT_GE(during["analysis_samples"].get<long>(), 590);
  const std::string before = file_text(dir / "summary.json");
  const Reanalysis re = reanalyse_run(dir);
  EXPECT_EQ(re.folder, dir / "reanalysis");
  EXPECT_NE(std::find(re.differs.begin(), re.differs.end(), "psi"), re.differs.end());
  EXPECT_EQ(file_text(dir / "summary.json"), before);
  // The same physics from coarser samples: Psi within a few of its own error bars.
  const auto frames = nlohmann::json::parse(file_text(dir / "reanalysis" / "summary.json"));
  EXPECT_EQ(frames["analysis_sample_strain"].get<double>(), 0.02);
  EXPECT_NEAR(frames["psi"].get<double>(), during["psi"].get<double>(),
              0.25 * during["psi"].get<double>());
}

std::string file_text(const std::filesystem::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A small pressure cell that reaches its (loosely tested) steady state within a few strains.
Config small_cell(bool diffusion) {
  Config c;
  c.scene.type = "pressure_shear";
  c.particles.n = 60;
  c.particles.phi_init = 0.74;
  c.flow.j = 1e-2;
  c.contact.ktilde = 1e3;
  c.run.seed = 3;
  c.run.strain = 6.0;
  c.steady.window = 1.0;
  c.steady.h_tolerance = 0.05;
  c.steady.mu_tolerance = 0.3;
  c.steady.measure_strain = 2.0;
  c.output.frame_strain = 0.02;
  c.analysis.sample_strain = 0.02;
  c.analysis.coarse_strain = 0.02;
  c.analysis.error_block = 0.5;
  c.analysis.diffusion = diffusion;
  c.analysis.msd_window_lo = 0.2;
  c.analysis.msd_window_hi = 0.5;
  c.analysis.vacf_max_lag = 0.3;
  return c;
}

// Every key of the pressure cell's summary (the steady window's error bars and stationarity
// signals, from the frames the observer sampled, the detection frame included) comes out of
// analyse unchanged, so summary.json and analysis.h5 are left as they are.
TEST(DiffusionRun, AnalyseReproducesThePressureCellExactly) {
  const ScratchDir dir;
  const nlohmann::json during = run_to_directory(small_cell(true), dir, false);
  ASSERT_TRUE(during["steady"].get<bool>());
  ASSERT_TRUE(during["phi_err"].is_number()) << during.dump();
  ASSERT_TRUE(during.contains("mu_top_minus_bottom_err"));
  ASSERT_TRUE(during.contains("window_blocks"));
  {
    // The run's H_change is the least-squares line through the H block means it reports,
    // times the window (blocks of equal width, so the window is their count times the spacing).
    const auto& b = during["window_blocks"];
    const std::size_t n = b["strain"].size();
    ASSERT_GE(n, 4u);
    ASSERT_EQ(b["H"].size(), n);
    const double slope =
        fit_line(b["strain"].get<std::vector<double>>(), b["H"].get<std::vector<double>>()).slope;
    const double span =
        static_cast<double>(n) * (b["strain"][1].get<double>() - b["strain"][0].get<double>());
    EXPECT_NEAR(during["H_change"].get<double>(), slope * span, 1e-9);
  }
  const std::string before = file_text(dir / "summary.json");
  const auto h5_time = std::filesystem::last_write_time(dir / "analysis.h5");
  const Reanalysis re = reanalyse_run(dir);
  EXPECT_TRUE(re.differs.empty()) << fmt::format("{}", fmt::join(re.differs, ", "));
  for (const auto& [key, value] : during.items()) EXPECT_EQ(value, re.summary[key]) << key;
  EXPECT_EQ(file_text(dir / "summary.json"), before);
  EXPECT_EQ(std::filesystem::last_write_time(dir / "analysis.h5"), h5_time);
  EXPECT_FALSE(std::filesystem::exists(dir / "reanalysis"));

  // A summary that disagrees with the trajectory (here an edited error bar; in practice an
  // older version's numbers) is never overwritten: the analysis goes beside it.
  nlohmann::json edited = during;
  edited["phi_err"] = 1.0;
  { std::ofstream(dir / "summary.json") << edited.dump(); }
  const std::string edited_text = file_text(dir / "summary.json");
  const Reanalysis beside = reanalyse_run(dir);
  EXPECT_EQ(beside.differs, std::vector<std::string>{"phi_err"});
  EXPECT_EQ(beside.folder, dir / "reanalysis");
  EXPECT_EQ(file_text(dir / "summary.json"), edited_text);
  EXPECT_EQ(std::filesystem::last_write_time(dir / "analysis.h5"), h5_time);
  ASSERT_TRUE(std::filesystem::exists(dir / "reanalysis" / "analysis.h5"));
  const auto written = nlohmann::json::parse(file_text(dir / "reanalysis" / "summary.json"));
  EXPECT_EQ(written["phi_err"], during["phi_err"]);
}

// A run made without the diffusion analysis gets it from analyse: its keys are added and
// analysis.h5 written, the run's own keys stay as they were.
TEST(DiffusionRun, AnalyseAddsWhatTheRunDidNotCompute) {
  const ScratchDir dir;
  const nlohmann::json during = run_to_directory(small_cell(false), dir, false);
  ASSERT_TRUE(during["steady"].get<bool>());
  ASSERT_FALSE(during.contains("D"));
  ASSERT_FALSE(std::filesystem::exists(dir / "analysis.h5"));
  const Reanalysis re = reanalyse_run(dir);
  EXPECT_TRUE(re.differs.empty()) << fmt::format("{}", fmt::join(re.differs, ", "));
  EXPECT_EQ(re.folder, dir.path());
  const auto written = nlohmann::json::parse(file_text(dir / "summary.json"));
  for (const auto& [key, value] : during.items()) EXPECT_EQ(value, written[key]) << key;
  EXPECT_TRUE(written.contains("D"));
  EXPECT_TRUE(written.contains("analysed_by"));
  EXPECT_TRUE(std::filesystem::exists(dir / "analysis.h5"));
}

// A window of fewer than 8 frames has no error bars: the summary says why (no "+- nan"), and
// analyse, counting the same frames, agrees.
TEST(DiffusionRun, TooFewFramesForErrorBarsIsSaidAndReproduced) {
  const ScratchDir dir;
  Config c = small_cell(false);
  c.output.frame_strain = 0.25;
  c.steady.measure_strain = 1.0;
  const nlohmann::json during = run_to_directory(c, dir, false);
  ASSERT_TRUE(during["steady"].get<bool>());
  EXPECT_FALSE(during.contains("phi_err"));
  ASSERT_TRUE(during.contains("steady_errors_note"));
  EXPECT_NE(during["steady_errors_note"].get<std::string>().find("frames in the measured window"),
            std::string::npos);
  const Reanalysis re = reanalyse_run(dir);
  EXPECT_TRUE(re.differs.empty()) << fmt::format("{}", fmt::join(re.differs, ", "));
  EXPECT_FALSE(re.summary.contains("phi_err"));
}

// The channel has no diffusion analysis: analyse refuses its run before reading anything.
TEST(DiffusionRun, AnalyseRefusesAChannelRun) {
  const ScratchDir dir;
  { std::ofstream(dir / "config.toml") << "[scene]\ntype = \"channel\"\n"; }
  { std::ofstream(dir / "summary.json") << "{\"steps\": 1}"; }
  EXPECT_THROW(reanalyse_run(dir), ConfigError);
  EXPECT_EQ(file_text(dir / "summary.json"), "{\"steps\": 1}");
  EXPECT_FALSE(std::filesystem::exists(dir / "analysis.h5"));
}

TEST(DiffusionRun, FrameStrainResolvedFromJ) {
  // 10 frames per persistence time Psi gammadot = 0.35 J^(1/4) (seed eq. 3.6b).
  const Config c = parse_config("[flow]\nJ = 1e-4\n", "test");
  EXPECT_NEAR(c.output.frame_strain, 0.0035, 1e-12);
  const Config d = parse_config("[flow]\nJ = 1e-4\n[output]\nframe_strain = 0.02\n", "test");
  EXPECT_EQ(d.output.frame_strain, 0.02);
}

}  // namespace
}  // namespace sheardiff
