// The in-run diffusion observer and `sheardiff analyse DIR` (reanalyse_run) see the same frames
// and give the same numbers, to the bit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "sheardiff/observe/diffusion_observer.hpp"
#include "sheardiff/simulation.hpp"

namespace sheardiff {
namespace {

TEST(DiffusionRun, AnalyseReproducesObserverExactly) {
  Config c;
  c.particles.n = 60;
  c.particles.phi_init = 0.7;
  c.flow.j = 1e-1;
  c.contact.ktilde = 1e3;
  c.run.strain = 1.5;
  c.run.transient_strain = 0.3;
  c.output.frame_strain = 0.01;
  c.analysis.msd_window_lo = 0.2;
  c.analysis.msd_window_hi = 0.5;
  c.analysis.reference_times = 50;
  c.analysis.vacf_max_lag = 0.3;
  const auto dir = std::filesystem::temp_directory_path() / "sheardiff_test_diffusion_run";
  std::filesystem::remove_all(dir);
  const nlohmann::json during = run_to_directory(c, dir, false);
  ASSERT_TRUE(during.contains("D"));
  ASSERT_TRUE(std::filesystem::exists(dir / "analysis.h5"));
  const nlohmann::json after = reanalyse_run(dir);
  for (const char* key : {"D", "D_err", "D_regression_stderr", "dv", "psi", "psi_e", "step_length", "msd_window",
                          "msd_window_slope", "analysis_frames", "diffusion_consistency"})
    EXPECT_EQ(during[key], after[key]) << key;
  // Physical sanity of the numbers themselves: a sheared suspension diffuses and fluctuates.
  EXPECT_GT(during["D"].get<double>(), 0.0);
  EXPECT_GT(during["dv"].get<double>(), 0.0);
  EXPECT_GT(during["psi"].get<double>(), 0.0);
  // Frames are written at the first step past each multiple of 0.01, so the one at 0.3 lies just
  // past the transient: 0.30, 0.31, ..., 1.50.
  EXPECT_EQ(during["analysis_frames"].get<long>(), 121);
  std::filesystem::remove_all(dir);
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
