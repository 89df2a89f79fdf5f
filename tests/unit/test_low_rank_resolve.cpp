// The implicit integrator's re-solve after sliding contacts switch to sticking adds only their
// tangential stiffness dt kt w w^T; it is solved on the factor of the first solve (Woodbury)
// instead of a new assembly and factorisation. It must give the velocities and pair terms of
// the full solve, in the Lees-Edwards cell (image pairs: a right-hand side change too) and in
// the pressure cell (fixed-wall partners, and floating-wall partners, whose terms change the
// wall's border of the system: its column, diagonal and right-hand side).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

Config dense(const std::string& scene) {
  Config c;
  c.scene.type = scene;
  c.particles.n = 120;
  c.particles.phi_init = scene == "simple_shear" ? 0.78 : 0.75;
  c.flow.j = 1e-3;
  c.contact.ktilde = 1e4;
  c.run.seed = 4;
  return c;
}

// How the switched contacts reach the fast path: all in one pass on the factor, in two passes
// (the second reuses the first's columns of A^-1 W), or under the default limit, which
// refactorises when the terms would cost more back-substitutions than a factorisation.
enum class Passes { One, Two, DefaultLimit };

void expect_same_as_full_solve(const std::string& scene, Passes passes = Passes::One) {
  const Config c = dense(scene);
  Simulation sim(c);
  for (int k = 0; k < 60; ++k) sim.step();
  // The pressure cell: on until both walls touch the packing (the top wall falls onto it first),
  // the floating one in two places (one for each of two passes).
  const auto touching = [&](Motion m) {
    const Dynamics& dd = sim.dynamics();
    return std::count_if(
        dd.neighbours().pairs().begin(), dd.neighbours().pairs().end(),
        [&](const Pair& pr) { return pr.history.touching && dd.particles().motion[pr.j] == m; });
  };
  if (scene == "pressure_shear")
    for (int k = 0;
         k < 20000 && (touching(Motion::FloatingWall) < 2 || touching(Motion::FixedWall) == 0); ++k)
      sim.step();
  const Dynamics& d = sim.dynamics();
  const Particles& p = d.particles();
  const double dt = sim.integrator().last_dt();
  const FrictionalContact law{c.contact.ktilde, c.contact.kt_ratio * c.contact.ktilde,
                              c.contact.mu};
  const Lubrication lub{c.lubrication.delta, c.lubrication.h_max, true};
  std::vector<Pair> pairs = d.neighbours().pairs();
  std::vector<std::size_t> switched;
  int images = 0, walls = 0, floating = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!pairs[k].history.touching) continue;
    pairs[k].history.contact.sliding = true;
    switched.push_back(k);
    images += pairs[k].ky != 0;
    walls += p.motion[pairs[k].j] == Motion::FixedWall;
    floating += p.motion[pairs[k].j] == Motion::FloatingWall;
  }
  ASSERT_GT(switched.size(), 10u);
  if (scene == "simple_shear") {
    EXPECT_GT(images, 0) << "no Lees-Edwards image contact exercised";
  } else {
    EXPECT_GT(walls, 0) << "no fixed-wall contact exercised";
    EXPECT_GT(floating, 0) << "no floating-wall contact exercised";
  }
  const WallBodies* wall = d.wall_bodies();

  // Low-rank path: a solve with the contacts sliding, then switched to sticking.
  ForceBalance fast(lub, law, 3, true);
  if (passes != Passes::DefaultLimit) fast.set_max_low_rank_terms(switched.size());
  fast.on_rebuild(p, pairs);
  Velocities v_fast;
  ASSERT_TRUE(fast.solve(p, d.box(), d.flow(), pairs, dt, wall, v_fast));
  const std::size_t factorisations = fast.system().factorisations();
  if (passes == Passes::Two) {
    // Floating-wall contacts and the others dealt alternately to the two passes: in the
    // pressure cell each pass then changes the wall's border, and the second must build on the
    // first's A^-1 b.
    std::vector<std::size_t> first, second;
    int floating_first = 0, floating_second = 0, dealt[2] = {0, 0};
    for (std::size_t k : switched) {
      const bool to_wall = p.motion[pairs[k].j] == Motion::FloatingWall;
      const bool to_first = dealt[to_wall]++ % 2 == 0;
      (to_first ? first : second).push_back(k);
      if (to_wall) ++(to_first ? floating_first : floating_second);
    }
    if (scene == "pressure_shear") {
      ASSERT_GT(floating_first, 0) << "no floating-wall contact in the first pass";
      ASSERT_GT(floating_second, 0) << "no floating-wall contact in the second pass";
    }
    for (std::size_t k : first) pairs[k].history.contact.sliding = false;
    ASSERT_TRUE(fast.resolve_with_sticking(p, d.box(), d.flow(), pairs, first, dt, wall, v_fast));
    for (std::size_t k : second) pairs[k].history.contact.sliding = false;
    ASSERT_TRUE(fast.resolve_with_sticking(p, d.box(), d.flow(), pairs, second, dt, wall, v_fast));
  } else {
    for (std::size_t k : switched) pairs[k].history.contact.sliding = false;
    ASSERT_TRUE(
        fast.resolve_with_sticking(p, d.box(), d.flow(), pairs, switched, dt, wall, v_fast));
  }
  const ForceBalance::StickingCounts& counts = fast.sticking_counts();
  EXPECT_EQ(counts.switched, static_cast<long>(switched.size()));
  if (passes == Passes::DefaultLimit) {
    // N = 120: a factorisation costs a handful of back-substitutions, fewer than the switched.
    EXPECT_EQ(fast.system().factorisations(), factorisations + 1);
    EXPECT_EQ(counts.refactorised_budget, 1);
    EXPECT_EQ(counts.low_rank, 0);
  } else {
    EXPECT_EQ(fast.system().factorisations(), factorisations);
    EXPECT_EQ(fast.system().low_rank_terms(), switched.size());
    EXPECT_EQ(counts.refactorised_budget, 0);
    EXPECT_EQ(counts.low_rank, passes == Passes::Two ? 2 : 1);
  }

  // Full path: assembled with them sticking from the start.
  ForceBalance full(lub, law, 3, true);
  full.on_rebuild(p, pairs);
  Velocities v_full;
  ASSERT_TRUE(full.solve(p, d.box(), d.flow(), pairs, dt, wall, v_full));

  double scale = 0.0, diff = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    scale = std::max(scale, v_full.u[i].cwiseAbs().maxCoeff());
    diff = std::max(diff, (v_fast.u[i] - v_full.u[i]).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(diff, 1e-9 * scale) << "walls " << walls;
  EXPECT_NEAR(v_fast.wall_v, v_full.wall_v, 1e-9 * std::max(scale, std::abs(v_full.wall_v)));
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!full.terms()[k].on) continue;
    ASSERT_LT((fast.terms()[k].m - full.terms()[k].m).cwiseAbs().maxCoeff(),
              1e-12 * full.terms()[k].m.cwiseAbs().maxCoeff())
        << "pair " << k;
  }
}

TEST(LowRankResolve, SameAsFullSolveLeesEdwards) {
  expect_same_as_full_solve("simple_shear");
}

TEST(LowRankResolve, SameAsFullSolvePressureCell) {
  expect_same_as_full_solve("pressure_shear");
}

TEST(LowRankResolve, TwoPassesKeepTheFirstColumns) {
  expect_same_as_full_solve("simple_shear", Passes::Two);
  expect_same_as_full_solve("pressure_shear", Passes::Two);
}

TEST(LowRankResolve, ManySwitchedContactsRefactorise) {
  expect_same_as_full_solve("simple_shear", Passes::DefaultLimit);
}

}  // namespace
}  // namespace sheardiff
