// The frames of a run: the first at step 0 (the initial configuration, its velocities and
// stresses at rest), then one every output.frame_strain exactly, however the step size varies
// (the step before a frame is shortened to land on it).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "scratch_dir.hpp"
#include "sheardiff/engine.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

namespace fs = std::filesystem;

Config small(const std::string& scene) {
  Config c;
  c.scene.type = scene;
  c.particles.n = 80;
  c.particles.phi_init = scene == "pressure_shear" ? 0.72 : 0.76;
  c.flow.j = 3e-2;
  c.contact.ktilde = 1e3;
  c.run.seed = 4;
  c.run.strain = 1.0;
  c.output.frame_strain = 0.02;
  c.analysis.diffusion = false;
  return c;
}

class FramesOfEachScene : public ::testing::TestWithParam<const char*> {};

TEST_P(FramesOfEachScene, FirstAtStepZeroThenEvenlySpaced) {
  const Config cfg = small(GetParam());
  const ScratchDir dir;
  run_to_directory(cfg, dir, false);
  const fs::path traj = dir / "trajectory.h5";
  // The initial configuration, as the engine builds it from the same config.
  const Simulation initial(cfg);
  const H5mdFrame first = read_h5md_frame(traj, 0);
  EXPECT_EQ(first.step, 0);
  EXPECT_EQ(first.time, 0.0);
  const auto& x0 = initial.dynamics().particles().position;
  ASSERT_EQ(first.position.size(), x0.size());
  for (std::size_t i = 0; i < x0.size(); ++i) {
    ASSERT_EQ(first.position[i].x(), x0[i].x()) << i;
    ASSERT_EQ(first.position[i].y(), x0[i].y()) << i;
  }
  // Velocities at rest: solved, finite, not all zero (the imposed shear moves the discs).
  double speed = 0.0;
  for (const auto& u : first.velocity) {
    ASSERT_TRUE(std::isfinite(u.x()) && std::isfinite(u.y()));
    speed = std::max(speed, std::abs(u.x()));
  }
  EXPECT_GT(speed, 0.0);
  // One frame every frame_strain, to round-off (the steps between frames vary in size).
  const auto strain = read_h5md_observable(traj, "strain").value;
  ASSERT_EQ(strain.size(), 51u);  // strain 0, 0.02, ..., 1.0
  double worst = 0.0;
  for (std::size_t k = 0; k < strain.size(); ++k)
    worst = std::max(worst, std::abs(strain[k] - 0.02 * static_cast<double>(k)));
  EXPECT_LT(worst, 1e-12) << "frames off their strains";
  const H5mdFrame second = read_h5md_frame(traj, 1), third = read_h5md_frame(traj, 2);
  EXPECT_NEAR(third.time - second.time, second.time - first.time, 1e-12 * third.time);
}

// A fixed integrator.dt is the step a convergence study asks for: never shortened to land on a
// frame, whichever integrator takes it.
TEST(Frames, AFixedStepIsNeverShortened) {
  for (const auto type : {IntegratorType::Euler, IntegratorType::Heun, IntegratorType::Implicit}) {
    Config cfg = small("simple_shear");
    cfg.integrator.type = type;
    cfg.integrator.dt = 1e-3;
    Simulation sim(cfg);
    Dynamics& d = sim.dynamics();
    d.set_landing(d.strain() + 0.25 * cfg.integrator.dt * d.flow().clock_rate());
    ASSERT_TRUE(sim.try_step());
    EXPECT_EQ(sim.integrator().last_dt(), cfg.integrator.dt) << static_cast<int>(type);
  }
  // An adaptive step is.
  Config cfg = small("simple_shear");
  Simulation sim(cfg);
  Dynamics& d = sim.dynamics();
  ASSERT_TRUE(sim.try_step());
  const double landing = d.strain() + 1e-6;
  d.set_landing(landing);
  ASSERT_TRUE(sim.try_step());
  EXPECT_NEAR(d.strain(), landing, 1e-15);
}

// The solve at rest for the frame at step 0 leaves the run as it would be without it, also where
// the first step does not itself begin with that solve (implicit springs with a fixed dt; the
// adaptive cases are pinned in ReferenceRuns.TheFrameAtRestLeavesTheRunsUnchanged).
TEST(Frames, TheSolveAtRestChangesNothingWithAFixedImplicitStep) {
  Config cfg = small("pressure_shear");
  cfg.integrator.dt = 2e-3;
  cfg.solver.cholesky = "eigen";
  Simulation a(cfg), b(cfg);
  ASSERT_TRUE(b.solve_at_rest());
  for (int k = 0; k < 300; ++k) ASSERT_TRUE(a.try_step() && b.try_step()) << k;
  const auto& xa = a.dynamics().particles().position;
  const auto& xb = b.dynamics().particles().position;
  for (std::size_t i = 0; i < xa.size(); ++i) {
    ASSERT_EQ(xa[i].x(), xb[i].x()) << i;
    ASSERT_EQ(xa[i].y(), xb[i].y()) << i;
  }
  EXPECT_EQ(a.dynamics().height(), b.dynamics().height());
}

INSTANTIATE_TEST_SUITE_P(Scenes, FramesOfEachScene,
                         ::testing::Values("simple_shear", "pressure_shear"));

}  // namespace
}  // namespace sheardiff
