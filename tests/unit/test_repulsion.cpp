// The electrostatic double-layer repulsion F = F0 exp(-h / lambda) (interactions/repulsion.hpp):
// its force-displacement law in one solve, the gap at which it balances a load through the whole
// engine, its config keys and that it is off unless asked for.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

// Two small discs on a horizontal line in a quiescent 20 x 20 cell at surface gap h.
Scene two_discs(double h) {
  Scene sc;
  sc.particles.resize(2);
  sc.particles.n_mobile = 2;
  const double r = 1.0 + h;
  sc.particles.position = {Vec2(10.0 - 0.5 * r, 10.0), Vec2(10.0 + 0.5 * r, 10.0)};
  sc.particles.unwrapped = sc.particles.position;
  sc.particles.radius = {0.5, 0.5};
  sc.particles.species = {0, 0};
  sc.box.lx = sc.box.ly = 20.0;
  sc.box.lees_edwards = true;
  sc.flow.gammadot = 0.0;
  return sc;
}

Config repulsive_config(double f0, double lambda) {
  Config cfg;
  cfg.flow.j = 0.0;  // quiescent fluid
  cfg.lubrication.enabled = false;
  cfg.contact.mu = 0.0;
  cfg.repulsion.f0 = f0;
  cfg.repulsion.lambda = lambda;
  cfg.neighbour.skin = 1.0;  // no rebuild while the discs move
  return cfg;
}

TEST(DoubleLayerRepulsion, IsOffByDefault) {
  const Config def;
  EXPECT_EQ(def.repulsion.f0, 0.0);
  EXPECT_FALSE(PairLaws::from(def).get<DoubleLayerRepulsion>().has_value());
  const Config parsed = parse_config("[scene]\ntype = \"pressure_shear\"\n", "t.toml");
  EXPECT_FALSE(PairLaws::from(parsed).get<DoubleLayerRepulsion>().has_value());
  // Nothing else moves: the neighbour range and stability limit are lubrication's and contact's.
  EXPECT_EQ(interaction_range_factor(parsed), 1.0 + 0.5 * parsed.lubrication.h_max);
  Config on = parsed;
  on.repulsion.f0 = 1e4;  // stiffness F0 / lambda = 5e5 P d, 50 kn: the faster mode
  EXPECT_TRUE(PairLaws::from(on).get<DoubleLayerRepulsion>().has_value());
  EXPECT_LT(explicit_stability_dt(on), explicit_stability_dt(parsed));
}

TEST(DoubleLayerRepulsion, KeysAreValidatedByName) {
  for (const std::string bad : {"F0 = -1.0", "lambda = 0.0", "lambda = 2.0", "cutoff = 0.5"}) {
    try {
      parse_config("[repulsion]\n" + bad + "\n", "t.toml");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("repulsion." + bad.substr(0, bad.find(' '))),
                std::string::npos)
          << e.what();
    }
  }
  const Config c = parse_config("[repulsion]\nF0 = 2.5\nlambda = 0.05\ncutoff = 6\n", "t.toml");
  EXPECT_EQ(c.repulsion.f0, 2.5);
  EXPECT_EQ(c.repulsion.lambda, 0.05);
  EXPECT_EQ(c.repulsion.cutoff, 6.0);
}

// One solve at surface gap h: the pair's force is F0 exp(-h / lambda) along the line of centres,
// and each disc moves apart at F / (3 pi d) against its drag.
TEST(DoubleLayerRepulsion, ForceFollowsTheExponentialLawOfTheGap) {
  const double f0 = 2.0, lambda = 0.02;
  for (const double h : {0.001, 0.03, 0.1, 0.19}) {
    Simulation sim(repulsive_config(f0, lambda), two_discs(h));
    Dynamics& d = sim.dynamics();
    d.begin_step();
    Velocities v;
    ASSERT_TRUE(d.solve(0.0, v));
    const PairTerm& t = d.force_balance().terms().at(0);
    ASSERT_TRUE(t.on) << "h " << h;
    // The gap of the placed discs (h up to rounding of centres at x ~ 10).
    const double gap = t.g.r - t.g.s;
    ASSERT_NEAR(gap, h, 1e-13);
    const double f = f0 * std::exp(-gap / lambda);
    EXPECT_NEAR(t.f[0], -f, 1e-14 * f0) << "h " << h;  // on disc i, away from j
    EXPECT_NEAR(t.f[3], f, 1e-14 * f0) << "h " << h;
    EXPECT_EQ(t.f[1], 0.0);
    EXPECT_EQ(t.f[2], 0.0);
    const double zeta = 3.0 * kPi;  // drag of a disc of diameter d
    EXPECT_NEAR(v.u[1].x(), f / zeta, 1e-12 * f0) << "h " << h;
    EXPECT_NEAR(v.u[0].x(), -f / zeta, 1e-12 * f0) << "h " << h;
    EXPECT_NEAR(v.u[0].z(), 0.0, 1e-15);  // central: no torque
  }
  // Beyond its cut-off (10 lambda) it does not act at all.
  Simulation far(repulsive_config(f0, lambda), two_discs(0.21));
  far.dynamics().begin_step();
  Velocities v;
  ASSERT_TRUE(far.dynamics().solve(0.0, v));
  EXPECT_FALSE(far.dynamics().force_balance().terms().at(0).on);
  EXPECT_EQ(v.u[1].x(), 0.0);
}

// Two discs pressed together by opposite external forces Fext come to rest where the repulsion
// balances the load: F0 exp(-h / lambda) = Fext, h = lambda ln(F0 / Fext).
TEST(DoubleLayerRepulsion, BalancesALoadAtTheAnalyticGap) {
  const double f0 = 1.0, lambda = 0.05, load = 0.2;
  for (const auto type : {IntegratorType::Implicit, IntegratorType::Euler}) {
    Config cfg = repulsive_config(f0, lambda);
    cfg.integrator.type = type;
    cfg.integrator.dt = 0.02;
    Scene sc = two_discs(0.3);
    sc.particles.external = {Vec3(load, 0.0, 0.0), Vec3(-load, 0.0, 0.0)};
    Simulation sim(cfg, std::move(sc));
    for (int k = 0; k < 2000; ++k) sim.step();
    const Particles& p = sim.dynamics().particles();
    const double gap = (p.position[1] - p.position[0]).norm() - 1.0;
    EXPECT_NEAR(gap, lambda * std::log(f0 / load), 1e-9) << to_string(type);
  }
}

}  // namespace
}  // namespace sheardiff
