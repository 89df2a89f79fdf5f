// Run health (issue 6): each failure is forced and must be detected and reported, never
// finish silently wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

#include "sheardiff/core/archive.hpp"
#include "sheardiff/observe/run_health.hpp"
#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

namespace fs = std::filesystem;

Config small(const std::string& scene = "simple_shear") {
  Config c;
  c.scene.type = scene;
  c.particles.n = 40;
  c.particles.phi_init = 0.75;
  c.contact.ktilde = 1e3;
  c.run.strain = 0.05;
  c.analysis.diffusion = false;
  c.output.trajectory = false;
  c.output.checkpoint_strain = 0.0;
  resolve_defaults(c);
  return c;
}

fs::path fresh_dir(const std::string& name) {
  const auto dir =
      fs::temp_directory_path() / ("sheardiff_health_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

std::string slurp(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(RunHealth, HealthyRunPassesAndReportsItsMaxima) {
  const Config c = small();
  const auto dir = fresh_dir("ok");
  const auto js = run_to_directory(c, dir, false);
  ASSERT_TRUE(js.contains("health"));
  EXPECT_GT(js["health"]["max_overlap"].get<double>(), 0.0);
  EXPECT_LT(js["health"]["max_overlap"].get<double>(), c.health.max_overlap);
  EXPECT_LT(js["health"]["max_residual"].get<double>(), 1e-8);
  EXPECT_FALSE(fs::exists(dir / "diagnostic.txt"));
  fs::remove_all(dir);
}

// The explicit integrator with a fixed dt 100x its stability limit (validate_run_inputs would
// reject this config; run_to_directory is called directly, as a library user could).
TEST(RunHealth, AbsurdExplicitStepIsStoppedNotSilentlyWrong) {
  Config c = small();
  c.integrator.type = IntegratorType::Euler;
  c.integrator.dt = 100.0 * explicit_stability_dt(c);
  c.run.strain = 1.0;  // 40 steps: an unstable mode grows ~100x per step
  c.output.checkpoint_strain = 0.01;
  EXPECT_THROW(validate_run_inputs(c, "test"), ConfigError);
  const auto dir = fresh_dir("explicit");
  try {
    const auto js = run_to_directory(c, dir, false);
    FAIL() << "the run finished: " << js.dump(1);
  } catch (const RunUnhealthy& e) {
    const HealthReport& r = e.report;
    std::cout << e.what() << "\n";
    EXPECT_TRUE(r.problem == HealthProblem::Overlap || r.problem == HealthProblem::NonFinite ||
                r.problem == HealthProblem::SolverFailure)
        << e.what();
    EXPECT_GT(r.step, 0);
    EXPECT_NE(std::string(e.what()).find("integrator.dt"), std::string::npos) << e.what();
    EXPECT_TRUE(fs::exists(dir / "diagnostic.txt"));
    EXPECT_NE(slurp(dir / "diagnostic.txt").find("# problem: "), std::string::npos);
    EXPECT_EQ(fs::exists(dir / "checkpoint.bin"), r.state_finite);
  }
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  fs::remove_all(dir);
}

TEST(RunHealth, OverlapAboveLimitNamesThePair) {
  Simulation sim(small());
  sim.step();
  Dynamics& d = sim.dynamics();
  RunHealth health(sim.config(), d);
  // Pull the second particle of a listed pair onto the first: 0.5 d overlap.
  const Pair pr = d.neighbours().pairs().front();
  auto& p = d.particles_mut();
  const Vec2 rij = p.position[pr.j] + d.box().image_shift(pr.kx, pr.ky) - p.position[pr.i];
  p.position[pr.j] -= rij - rij.normalized() * (p.radius[pr.i] + p.radius[pr.j] - 0.5);
  const auto r = health.check(d, sim.integrator().velocities(), sim.integrator().last_dt());
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->problem, HealthProblem::Overlap) << r->message();
  EXPECT_NE(std::find(r->particles.begin(), r->particles.end(), pr.j), r->particles.end());
  EXPECT_NEAR(RunHealth::max_overlap(d), 0.5, 1e-9);
  EXPECT_NE(r->message().find("health.max_overlap"), std::string::npos);
}

TEST(RunHealth, NonFinitePositionIsNamedAndNotCheckpointed) {
  Simulation sim(small());
  sim.step();
  RunHealth health(sim.config(), sim.dynamics());
  sim.dynamics().particles_mut().position[7].x() = std::numeric_limits<double>::quiet_NaN();
  const auto r = health.check(sim.dynamics(), sim.integrator().velocities(), 1e-3);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->problem, HealthProblem::NonFinite);
  EXPECT_EQ(r->particles, std::vector<int>{7});
  EXPECT_FALSE(r->state_finite);
}

TEST(RunHealth, FailedSolveIsReported) {
  Simulation sim(small());
  auto& p = sim.dynamics().particles_mut();
  p.external.assign(p.size(), Vec3::Zero());
  p.external[3].x() = std::numeric_limits<double>::infinity();
  RunHealth health(sim.config(), sim.dynamics());
  ASSERT_FALSE(sim.try_step());
  const HealthReport r = health.solver_failure(sim.dynamics(), sim.integrator().velocities());
  EXPECT_EQ(r.problem, HealthProblem::SolverFailure);
  EXPECT_TRUE(r.state_finite);
  EXPECT_EQ(r.step, 0);
}

TEST(RunHealth, ResidualAboveLimitIsReported) {
  Config c = small();
  c.health.max_residual = 1e-300;  // no real solve gets there
  Simulation sim(c);
  sim.dynamics().force_balance().set_check_residual(true);
  sim.step();
  RunHealth health(c, sim.dynamics());
  const auto r = health.check(sim.dynamics(), sim.integrator().velocities(), 1e-3);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->problem, HealthProblem::Residual) << r->message();
}

TEST(RunHealth, WallThrownOffOrParticleThroughWallIsReported) {
  Config c = small("pressure_shear");
  Simulation sim(c);
  sim.step();
  RunHealth health(c, sim.dynamics());
  Velocities v = sim.integrator().velocities();
  EXPECT_FALSE(health.check(sim.dynamics(), v, sim.integrator().last_dt()).has_value());
  v.wall_v = 1e3;
  auto r = health.check(sim.dynamics(), v, 1e-2);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->problem, HealthProblem::WallEscape) << r->message();

  v.wall_v = 0.0;
  sim.dynamics().particles_mut().position[5].y() += 10.0 * sim.dynamics().height();
  r = health.check(sim.dynamics(), v, 1e-2);
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->problem, HealthProblem::WallEscape) << r->message();
  EXPECT_EQ(r->particles, std::vector<int>{5});
}

TEST(RunHealth, FixedStepEndsExactlyAtRunStrain) {
  Config c = small();
  c.run.strain = 0.01;
  c.integrator.dt = 0.3e-3 / c.flow.j;  // 0.01 / 3e-4 = 33.3 steps
  const auto dir = fresh_dir("fixed");
  const auto js = run_to_directory(c, dir, false);
  EXPECT_EQ(js["steps"].get<long>(), 34);
  EXPECT_NEAR(js["strain"].get<double>(), c.run.strain, 1e-14);
  fs::remove_all(dir);
}

TEST(Archive, EmptyVectorsRoundTrip) {
  std::vector<double> empty, other = {1.0};
  std::string s;
  Archive w = Archive::writer();
  w.io(empty), w.io(s), w.io(other);
  Archive r = Archive::reader(w.bytes());
  std::vector<double> e2 = {5.0}, o2;
  std::string s2 = "x";
  r.io(e2), r.io(s2), r.io(o2);
  EXPECT_TRUE(e2.empty());
  EXPECT_TRUE(s2.empty());
  EXPECT_EQ(o2, other);
  EXPECT_TRUE(r.at_end());
}

}  // namespace
}  // namespace sheardiff
