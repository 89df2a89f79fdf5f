// A scene pays only for what it uses (issue 5): no rotational unknowns without friction and
// tangential lubrication, no factorisation without any pair coupling, no wall unknown in simple
// shear, no neighbour rebuild before the skin is used up, no observer that was not asked for.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "sheardiff/observe/observer.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/run_parts.hpp"

namespace sheardiff {
namespace {

Config frictionless(const std::string& scene) {
  Config c;
  c.scene.type = scene;
  c.particles.n = 80;
  c.particles.phi_init = 0.74;
  c.flow.j = 1e-2;
  c.contact.ktilde = 1e4;
  c.contact.mu = 0.0;
  c.lubrication.tangential = false;
  return c;
}

double max_position_difference(const Dynamics& a, const Dynamics& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.particles().size(); ++i)
    m = std::max(m, (a.particles().unwrapped[i] - b.particles().unwrapped[i]).norm());
  return m;
}

// The rotational rows decouple when nothing exerts a torque but the drag, so dropping them
// changes only the round-off of the factorisation (a different matrix ordering).
void expect_same_trajectory(Config c, IntegratorType type, int steps) {
  c.integrator.type = type;
  Config with = c;
  with.solver.rotations = "always";
  Simulation two(c), three(with);
  ASSERT_EQ(two.dynamics().force_balance().system().dof(), 2);
  ASSERT_EQ(three.dynamics().force_balance().system().dof(), 3);
  double max_overlap = 0.0;
  for (int k = 0; k < steps; ++k) {
    two.step();
    three.step();
    ASSERT_NEAR(two.integrator().last_dt(), three.integrator().last_dt(),
                1e-9 * three.integrator().last_dt());
    max_overlap = std::max(max_overlap, two.sample().max_overlap);
  }
  EXPECT_GT(max_overlap, 0.0) << "the test should exercise contacts";
  EXPECT_NEAR(two.dynamics().strain(), three.dynamics().strain(),
              1e-12 * three.dynamics().strain());
  // Positions are O(10 d); round-off amplified over a few hundred steps stays far below 1e-9 d.
  EXPECT_LT(max_position_difference(two.dynamics(), three.dynamics()), 1e-9);
  // omega = omega_inf for every mobile particle: what the decoupled rotational row gives.
  const auto& u2 = two.integrator().velocities().u;
  const auto& u3 = three.integrator().velocities().u;
  for (std::size_t i = 0; i < two.dynamics().particles().n_mobile; ++i) {
    EXPECT_NEAR(u2[i].z(), -0.5 * c.flow.j, 1e-15);
    EXPECT_NEAR(u3[i].z(), -0.5 * c.flow.j, 1e-9);
  }
}

TEST(SkipUnneeded, NoRotationalUnknownsWithoutFrictionSimpleShear) {
  for (IntegratorType type : {IntegratorType::Implicit, IntegratorType::Euler}) {
    SCOPED_TRACE(to_string(type));
    expect_same_trajectory(frictionless("simple_shear"), type, 300);
  }
}

TEST(SkipUnneeded, NoRotationalUnknownsWithoutFrictionPressureShear) {
  expect_same_trajectory(frictionless("pressure_shear"), IntegratorType::Implicit, 300);
}

TEST(SkipUnneeded, RotationsKeptWhenSomethingCouplesThem) {
  Config c = frictionless("simple_shear");
  EXPECT_FALSE(rotational_unknowns(c));
  c.lubrication.enabled = false;  // no lubrication at all: also decoupled
  EXPECT_FALSE(rotational_unknowns(c));
  c = frictionless("simple_shear");
  c.contact.mu = 0.5;  // friction: tangential springs exert torques
  EXPECT_TRUE(rotational_unknowns(c));
  c = frictionless("simple_shear");
  c.contact.kt_ratio = 0.0;  // mu > 0 but kt = 0 is frictionless as well
  c.contact.mu = 0.5;
  EXPECT_FALSE(rotational_unknowns(c));
  c = frictionless("simple_shear");
  c.lubrication.tangential = true;  // shear-rotation coupling of lubrication
  EXPECT_TRUE(rotational_unknowns(c));
  EXPECT_TRUE(rotational_unknowns(Config{}));
}

TEST(SkipUnneeded, TangentialLubricationOffLeavesSqueezeOnly) {
  const Lubrication on{0.01, 0.5, true}, off{0.01, 0.5, false};
  for (double h : {-0.01, 0.0, 0.05, 0.3}) {
    const PairResistance a = on.coefficients(0.5, 0.7, h), b = off.coefficients(0.5, 0.7, h);
    EXPECT_EQ(a.xa, b.xa);
    EXPECT_GT(a.ya, 0.0);
    EXPECT_EQ(b.ya, 0.0);
    EXPECT_EQ(b.beta_i + b.beta_j + b.gam_ii + b.gam_jj + b.gam_ij, 0.0);
  }
}

TEST(SkipUnneeded, NoFactorisationWithoutLubricationAndExplicitSprings) {
  Config c = frictionless("simple_shear");
  c.lubrication.enabled = false;
  c.integrator.type = IntegratorType::Euler;
  Simulation sim(c);
  for (int k = 0; k < 50; ++k) sim.step();
  const ResistanceSystem& rs = sim.dynamics().force_balance().system();
  EXPECT_EQ(rs.factorisations(), 0u);
  EXPECT_EQ(rs.analyses(), 0u);
  EXPECT_EQ(rs.matrix().nonZeros(), 0);
  EXPECT_EQ(rs.dof(), 2);
}

TEST(SkipUnneeded, NoWallUnknownInSimpleShear) {
  Simulation sim(frictionless("simple_shear"));
  sim.step();
  EXPECT_FALSE(sim.dynamics().walls().has_value());
  EXPECT_EQ(sim.dynamics().wall_bodies(), nullptr);
  EXPECT_EQ(sim.dynamics().force_balance().system().wall_column().size(),
            static_cast<Eigen::Index>(sim.dynamics().force_balance().system().unknowns()));
  EXPECT_EQ(sim.dynamics().force_balance().system().wall_column().squaredNorm(), 0.0);
}

TEST(SkipUnneeded, RebuildOnlyWhenTheSkinIsUsedUp) {
  Config c = frictionless("simple_shear");
  Simulation sim(c);
  const Dynamics& d = sim.dynamics();
  std::size_t rebuilds = d.neighbours().rebuilds();
  std::size_t analyses = d.force_balance().system().analyses();
  int rebuild_steps = 0;
  for (int k = 0; k < 400; ++k) {
    const bool due = d.neighbours().needs_rebuild();
    sim.step();
    const bool rebuilt = d.neighbours().rebuilds() != rebuilds;
    // A rebuild happens at the step after the skin was used up, and only then; the symbolic
    // analysis follows the rebuilds one to one.
    EXPECT_EQ(rebuilt, due) << "step " << k;
    EXPECT_EQ(d.force_balance().system().analyses() - analyses,
              d.neighbours().rebuilds() - rebuilds);
    rebuild_steps += rebuilt;
    rebuilds = d.neighbours().rebuilds();
    analyses = d.force_balance().system().analyses();
  }
  EXPECT_GT(rebuild_steps, 0);
  EXPECT_LT(rebuild_steps, 400 / 10);
}

TEST(SkipUnneeded, UnrequestedObserversAreNotComposed) {
  const auto dir = std::filesystem::temp_directory_path() / "sheardiff_test_skip_observers";
  Config c = frictionless("simple_shear");
  c.analysis.diffusion = false;
  EXPECT_EQ(make_observers(c, dir).size(), 1u);  // rheology only
  c.analysis.diffusion = true;
  EXPECT_EQ(make_observers(c, dir).size(), 2u);
  c.scene.type = "pressure_shear";
  c.analysis.diffusion = false;
  EXPECT_EQ(make_observers(c, dir).size(), 3u);  // rheology, the pressure cell, its profiles
  c.observables.profiles = false;
  EXPECT_EQ(make_observers(c, dir).size(), 2u);  // rheology and the pressure cell
}

}  // namespace
}  // namespace sheardiff
