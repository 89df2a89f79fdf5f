// The per-step force/torque balance (docs/model.md sections 3, 6 and 7): the assembled linear
// system is solved to round-off, and the solved velocities balance drag and pair forces particle by
// particle.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/integrator/dynamics.hpp"
#include "sheardiff/run.hpp"
#include "sheardiff/scene/scene.hpp"
#include "sheardiff/solver/force_balance.hpp"
#include "sheardiff/solver/resistance_system.hpp"

namespace sheardiff {
namespace {

Config dense_config(IntegratorType type) {
  Config cfg;
  cfg.particles.n = 300;
  cfg.particles.phi_init = 0.78;
  cfg.flow.j = 1e-2;
  cfg.contact.ktilde = 1e4;
  cfg.integrator.type = type;
  return cfg;
}

std::size_t count_contacts(const Dynamics& d) {
  std::size_t n = 0;
  for (const Pair& pr : d.neighbours().pairs()) n += pr.history.touching ? 1 : 0;
  return n;
}

// Net generalised force (force x, force y, torque) on every mobile particle: the pair terms
// with the solved velocities plus the drag -D (U - U_inf). Also returns the largest pair force.
std::vector<Vec3> net_forces(const Dynamics& d, const Velocities& v, double& max_pair) {
  const Particles& p = d.particles();
  std::vector<Vec3> net(p.n_mobile, Vec3::Zero());
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    const Vec3 drag = StokesDrag::resistance(p.radius[i]);
    net[i] -= drag.cwiseProduct(v.u[i] - d.flow().velocity(p.position[i]));
    if (!p.external.empty()) net[i] += p.external[i];
  }
  max_pair = 0.0;
  const auto& pairs = d.neighbours().pairs();
  const auto& terms = d.force_balance().terms();
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (!terms[k].on) continue;  // not assembled this step (its m, f are not current)
    const Pair& pr = pairs[k];
    const Vec6 f = terms[k].force(v.u[pr.i], v.u[pr.j]);
    max_pair = std::max(max_pair, f.cwiseAbs().maxCoeff());
    net[pr.i] += f.head<3>();
    if (p.motion[pr.j] == Motion::Mobile) net[pr.j] += f.tail<3>();
  }
  return net;
}

class DenseForceBalance : public testing::TestWithParam<IntegratorType> {};

TEST_P(DenseForceBalance, SolvedToRoundOffAndBalancedPerParticle) {
  const IntegratorType type = GetParam();
  Simulation sim(dense_config(type));
  for (int s = 0; s < 4; ++s) sim.step();
  Dynamics& d = sim.dynamics();
  ASSERT_GT(count_contacts(d), 10u) << "the test needs a packing with contacts";

  // The residual of the integrator's own last solve.
  d.force_balance().set_check_residual(true);
  sim.step();
  EXPECT_LT(d.force_balance().last_residual(), 1e-10);

  // Solve again at the current configuration without moving, so that the pair terms, the
  // positions (drag against the local flow) and the velocities all belong to one solve.
  const bool implicit = sim.integrator().implicit_springs();
  const double dt = implicit ? sim.integrator().last_dt() : 0.0;
  if (implicit) {
    ASSERT_GT(dt, 0.0);
  }
  d.begin_step();
  Velocities v;
  ASSERT_TRUE(d.solve(dt, v));
  EXPECT_LT(d.force_balance().last_residual(), 1e-10);

  // Independent residual from the assembled system (lower triangle stored).
  const ResistanceSystem& sys = d.force_balance().system();
  const std::size_t n = d.particles().n_mobile;
  ASSERT_EQ(sys.unknowns(), 3 * n);
  VecX u(3 * n);
  for (std::size_t i = 0; i < n; ++i) u.segment<3>(3 * i) = v.u[i];
  const VecX r = sys.matrix().selfadjointView<Eigen::Lower>() * u - sys.rhs();
  EXPECT_LT(r.norm() / sys.rhs().norm(), 1e-10);

  // Every mobile particle: pair forces + drag = 0. The solve is exact up to round-off of a
  // well-conditioned SPD system (residual ~1e-15 |g|); 1e-8 of the largest pair force leaves
  // orders of magnitude of room while a missing or mis-signed term would be O(1).
  double max_pair = 0.0;
  const std::vector<Vec3> net = net_forces(d, v, max_pair);
  ASSERT_GT(max_pair, 0.0);
  double worst = 0.0;
  for (const Vec3& f : net) worst = std::max(worst, f.cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 1e-8 * max_pair) << "largest pair force " << max_pair;
}

INSTANTIATE_TEST_SUITE_P(Integrators, DenseForceBalance,
                         testing::Values(IntegratorType::Implicit, IntegratorType::Euler),
                         [](const testing::TestParamInfo<IntegratorType>& info) {
                           return std::string(to_string(info.param));
                         });

// ---- Labelling of a pair --------------------------------------------------------------------

TEST(PairAssembly, SwappingTheLabelsOfAPairGivesTheSameVelocities) {
  // The engine lists mobile pairs with i < j; the assembly also accepts i > j (the block then
  // goes to row i, column j). Both labellings describe the same physics: the pair law is
  // invariant under i <-> j (n -> -n, radii swapped), so the solves agree to round-off.
  Particles p;
  p.resize(3);
  p.n_mobile = 3;
  p.radius = {0.5, 0.7, 0.5};
  p.position = {Vec2(3.0, 4.0), Vec2(3.0, 4.0) + 1.23 * Vec2(std::cos(0.5), std::sin(0.5)),
                Vec2(3.0, 4.0) + 1.02 * Vec2(std::cos(2.5), std::sin(2.5))};
  p.unwrapped = p.position;
  p.external = {Vec3(0.1, -0.3, 0.02), Vec3(0.0, 0.2, -0.05), Vec3(-0.4, 0.1, 0.0)};
  Box box;
  box.lx = box.ly = 20.0;
  box.lees_edwards = true;
  const ImposedFlow flow{0.1, 0.0};
  const auto solve = [&](bool swapped) {
    std::vector<Pair> pairs(2);
    pairs[0].i = swapped ? 1 : 0;
    pairs[0].j = swapped ? 0 : 1;
    pairs[1].i = swapped ? 2 : 0;
    pairs[1].j = swapped ? 0 : 2;
    ForceBalance fb(Lubrication{0.01, 0.5}, FrictionalContact{1e4, 5e3, 0.5}, 3, true);
    fb.on_rebuild(p, pairs);
    Velocities v;
    EXPECT_TRUE(fb.solve(p, box, flow, pairs, 0.0, nullptr, v));
    EXPECT_TRUE(fb.terms()[0].on && fb.terms()[1].on);
    return v.u;
  };
  const std::vector<Vec3> a = solve(false), b = solve(true);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 3u);
  double scale = 0.0;
  for (const Vec3& u : a) scale = std::max(scale, u.cwiseAbs().maxCoeff());
  for (int i = 0; i < 3; ++i)
    EXPECT_LE((a[i] - b[i]).cwiseAbs().maxCoeff(), 1e-12 * scale) << "particle " << i;
  // The coupling is real: without the pairs the velocities would be drag-only.
  const Vec3 drag_only =
      flow.velocity(p.position[0]) + p.external[0].cwiseQuotient(StokesDrag::resistance(0.5));
  EXPECT_GT((a[0] - drag_only).cwiseAbs().maxCoeff(), 1e-3 * scale);
}

// ---- A lone particle follows the flow -------------------------------------------------------

Scene lone_particle_scene(double j, double y) {
  Scene sc;
  sc.particles.resize(1);
  sc.particles.n_mobile = 1;
  sc.particles.position[0] = Vec2(4.0, y);
  sc.particles.unwrapped[0] = sc.particles.position[0];
  sc.particles.radius[0] = 0.5;
  sc.box.lx = sc.box.ly = 10.0;
  sc.box.lees_edwards = true;
  sc.flow = ImposedFlow{j, 0.0};
  return sc;
}

class LoneParticle : public testing::TestWithParam<IntegratorType> {};

TEST_P(LoneParticle, MovesWithTheImposedFlow) {
  // No neighbours (its own images are 10 d away): drag alone, so U = U_inf exactly:
  // u = (J (y - y0), 0), omega = -J/2. The solve divides D U_inf by D: a few ulp.
  Config cfg;
  cfg.flow.j = 1e-2;
  cfg.integrator.type = GetParam();
  const double j = cfg.flow.j, y = 3.0;
  Simulation sim(cfg, lone_particle_scene(j, y));
  ASSERT_TRUE(sim.dynamics().neighbours().pairs().empty());
  sim.step();
  const Vec3 u = sim.integrator().velocities().u.at(0);
  const double scale = j * y;
  EXPECT_NEAR(u.x(), j * y, 1e-12 * scale);
  EXPECT_NEAR(u.y(), 0.0, 1e-12 * scale);
  EXPECT_NEAR(u.z(), -0.5 * j, 1e-12 * 0.5 * j);
  // It moved affinely: x advanced by J y dt, y unchanged.
  const double dt = sim.integrator().last_dt();
  ASSERT_GT(dt, 0.0);
  EXPECT_NEAR(sim.dynamics().particles().unwrapped[0].x(), 4.0 + j * y * dt, 1e-12);
  EXPECT_NEAR(sim.dynamics().particles().unwrapped[0].y(), y, 1e-14);
}

INSTANTIATE_TEST_SUITE_P(Integrators, LoneParticle,
                         testing::Values(IntegratorType::Implicit, IntegratorType::Euler,
                                         IntegratorType::Heun),
                         [](const testing::TestParamInfo<IntegratorType>& info) {
                           return std::string(to_string(info.param));
                         });

// ---- Drag only: the diagonal path --------------------------------------------------------------

// Four particles of both sizes, far apart (no pair within any cut-off), with imposed forces
// and torques. Drag only: U = U_inf + F / D with D = (3 pi d, 3 pi d, pi d^3).
Scene dilute_scene(double j) {
  Scene sc;
  sc.particles.resize(4);
  sc.particles.n_mobile = 4;
  sc.particles.position = {Vec2(2.0, 2.5), Vec2(12.0, 3.0), Vec2(4.0, 13.0), Vec2(15.0, 16.5)};
  sc.particles.unwrapped = sc.particles.position;
  sc.particles.radius = {0.5, 0.7, 0.7, 0.5};
  sc.particles.species = {0, 1, 1, 0};
  sc.particles.external = {Vec3(0.3, -0.2, 0.05), Vec3(-1.0, 0.5, -0.4), Vec3(0.0, 2.0, 0.0),
                           Vec3(0.7, 0.0, 1.1)};
  sc.box.lx = sc.box.ly = 20.0;
  sc.box.lees_edwards = true;
  sc.flow = ImposedFlow{j, 0.0};
  return sc;
}

Vec3 drag_only_velocity(const Vec2& x, double a, const Vec3& f, double j) {
  const double d = 2.0 * a;
  return Vec3(j * x.y() + f.x() / (3.0 * kPi * d), f.y() / (3.0 * kPi * d),
              -0.5 * j + f.z() / (kPi * d * d * d));
}

void expect_drag_only(const Scene& sc, const std::vector<Vec3>& u, double j) {
  ASSERT_GE(u.size(), sc.particles.n_mobile);
  for (std::size_t i = 0; i < sc.particles.n_mobile; ++i) {
    const Vec3 want = drag_only_velocity(sc.particles.position[i], sc.particles.radius[i],
                                         sc.particles.external[i], j);
    SCOPED_TRACE(testing::Message() << "particle " << i);
    // One division per component: round-off only.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(u[i][c], want[c], 1e-13 * want.cwiseAbs().maxCoeff());
  }
}

TEST(DragOnly, DiagonalPathMatchesAnalyticVelocities) {
  Config cfg;
  cfg.flow.j = 1e-2;
  cfg.lubrication.enabled = false;
  cfg.integrator.type = IntegratorType::Euler;
  const Scene sc = dilute_scene(cfg.flow.j);
  Simulation sim(cfg, sc);
  ASSERT_TRUE(sim.dynamics().neighbours().pairs().empty());
  // No lubrication and explicit springs: the diagonal-only path keeps no sparse matrix.
  EXPECT_EQ(sim.dynamics().force_balance().system().dof(), 3);
  EXPECT_EQ(sim.dynamics().force_balance().system().matrix().nonZeros(), 0);
  sim.step();
  EXPECT_EQ(sim.dynamics().force_balance().system().factorisations(), 0u);
  expect_drag_only(sc, sim.integrator().velocities().u, cfg.flow.j);
}

TEST(DragOnly, CoupledPathWithoutPairsGivesTheSameVelocities) {
  Config cfg;
  cfg.flow.j = 1e-2;
  const Scene sc = dilute_scene(cfg.flow.j);
  Simulation sim(cfg, sc);
  ASSERT_TRUE(sim.dynamics().neighbours().pairs().empty());
  sim.step();
  EXPECT_GT(sim.dynamics().force_balance().system().factorisations(), 0u);
  expect_drag_only(sc, sim.integrator().velocities().u, cfg.flow.j);
}

TEST(DragOnly, ResistanceSystemDiagonalAndFactorisedSolvesAgree) {
  // The same one-body system through both storage paths and both dof counts.
  const Scene sc = dilute_scene(0.05);
  const Particles& p = sc.particles;
  for (int dof : {3, 2}) {
    for (bool diagonal : {true, false}) {
      SCOPED_TRACE(testing::Message() << "dof=" << dof << " diagonal=" << diagonal);
      ResistanceSystem sys(dof);
      sys.set_pattern(p.n_mobile, {}, p, diagonal);
      ASSERT_EQ(sys.unknowns(), static_cast<std::size_t>(dof) * p.n_mobile);
      sys.clear();
      for (std::size_t i = 0; i < p.n_mobile; ++i) {
        const Vec3 drag = StokesDrag::resistance(p.radius[i]);
        const Vec3 force = drag.cwiseProduct(sc.flow.velocity(p.position[i])) + p.external[i];
        sys.add_self(static_cast<int>(i), drag, force);
      }
      VecX u;
      ASSERT_TRUE(sys.solve(u));
      ASSERT_EQ(u.size(), static_cast<Eigen::Index>(sys.unknowns()));
      for (std::size_t i = 0; i < p.n_mobile; ++i) {
        const Vec3 want = drag_only_velocity(p.position[i], p.radius[i], p.external[i], 0.05);
        for (int c = 0; c < dof; ++c)
          EXPECT_NEAR(u[dof * i + c], want[c], 1e-13 * want.cwiseAbs().maxCoeff());
      }
      EXPECT_LT(sys.residual(u, 0.0), 1e-14);
    }
  }
}

TEST(DragOnly, StokesDragCoefficients) {
  // 3 pi d for translation, pi d^3 for rotation (eta = 1): d = 1 and d = 1.4.
  EXPECT_NEAR(StokesDrag::resistance(0.5).x(), 3.0 * kPi, 1e-14);
  EXPECT_NEAR(StokesDrag::resistance(0.5).z(), kPi, 1e-14);
  EXPECT_NEAR(StokesDrag::resistance(0.7).y(), 4.2 * kPi, 1e-14);
  EXPECT_NEAR(StokesDrag::resistance(0.7).z(), 2.744 * kPi, 1e-14);
  const ImposedFlow flow{0.2, 1.5};
  const Vec3 v = flow.velocity(Vec2(7.0, 4.0));
  EXPECT_NEAR(v.x(), 0.2 * 2.5, 1e-15);
  EXPECT_EQ(v.y(), 0.0);
  EXPECT_NEAR(v.z(), -0.1, 1e-15);
}

}  // namespace
}  // namespace sheardiff
