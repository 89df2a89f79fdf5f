// The force balance of spheres (ForceBalance3, the engine's core instantiated in three
// dimensions) against closed forms and against the disc engine: a lone sphere in simple shear
// turns at -gammadot/2 about z; two spheres squeezed along an arbitrary line approach at the
// rate the drag and the squeeze resistance give; a sphere pressed on a wall sphere comes to rest
// at the overlap F / kn; and a packing of spheres whose centres lie in one plane moves exactly as
// the same packing of discs (the 3D operator restricted to a plane is the 2D one), with and
// without walls, explicit and implicit springs, and after the sticking re-solve.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/engine.hpp"
#include "sheardiff/neighbour/neighbour_list.hpp"
#include "sheardiff/solver/force_balance.hpp"
#include "spheres_in_a_plane.hpp"

namespace sheardiff {
namespace {

// A cell of spheres periodic in x, y (Lees-Edwards) and z, large enough for one or two spheres.
Box3 open_box(double l) {
  Box3 box;
  box.lx = box.ly = box.lz = l;
  box.lees_edwards = true;
  return box;
}

Particles3 spheres(const std::vector<Space3>& at, const std::vector<double>& radius) {
  Particles3 p;
  p.resize(at.size());
  p.n_mobile = at.size();
  p.position = p.unwrapped = at;
  p.radius = radius;
  return p;
}

TEST(SphereForceBalance, LoneSphereInShearFollowsTheFlowAndTurnsAtMinusHalfTheShearRateAboutZ) {
  const double gammadot = 0.37;
  const Space3 x(2.0, 3.1, 4.0);
  Particles3 p = spheres({x}, {0.7});
  const Box3 box = open_box(10.0);
  const ImposedFlow flow{gammadot, 0.0};
  NeighbourList3 list(1.25, 0.3);
  list.rebuild(p, box);
  ForceBalance3 fb(Lubrication{0.01, 0.5}, FrictionalContact{1e4, 5e3, 0.5}, 6, false);
  fb.on_rebuild(p, list.pairs());
  VelocitiesOf<Dim3> v;
  ASSERT_TRUE(fb.solve(p, box, flow, list.pairs(), 0.0, nullptr, v));
  Vec6 expected;
  expected << gammadot * x.y(), 0.0, 0.0, 0.0, 0.0, -0.5 * gammadot;
  EXPECT_LT((v.u[0] - expected).norm(), 1e-14);
}

TEST(SphereForceBalance, TwoSpheresSqueezedAlongAnArbitraryLineApproachAtTheDragAndSqueezeRate) {
  // Equal spheres, radius a, gap h = 0.05 s along n, pushed together by F: by symmetry
  // u_i = -u_j = u n with -zeta u - XA (2 u) + F = 0, zeta = 6 pi a and XA the squeeze
  // coefficient at that gap (regularised by delta; the closed form itself is tested in
  // test_pair_laws_3d.cpp): the pair approaches at 2 F / (zeta + 2 XA). No tangential motion and
  // no rotation.
  const double a = 0.5, h = 0.05, force = 2.0;
  const Space3 n = Space3(1.0, -2.0, 0.7).normalized();
  const Space3 xi(3.0, 3.0, 3.0);
  const Space3 xj = xi + (2.0 * a) * (1.0 + 0.5 * h) * n;
  Particles3 p = spheres({xi, xj}, {a, a});
  Vec6 push = Vec6::Zero();
  push.head<3>() = force * n;
  p.external = {push, Vec6(-push)};
  const Box3 box = open_box(8.0);
  const ImposedFlow flow{0.0, 0.0};
  const Lubrication lub{0.01, 0.5};
  NeighbourList3 list(lub.range_factor(), 0.3);
  list.rebuild(p, box);
  ASSERT_EQ(list.pairs().size(), 1u);
  ForceBalance3 fb(lub, FrictionalContact{1e4, 5e3, 0.5}, 6, false);
  fb.on_rebuild(p, list.pairs());
  VelocitiesOf<Dim3> v;
  ASSERT_TRUE(fb.solve(p, box, flow, list.pairs(), 0.0, nullptr, v));
  const double xa = lub.coefficients(a, a, h).xa;
  const double approach = 2.0 * force / (6.0 * kPi * a + 2.0 * xa);
  const Space3 ui = v.u[0].head<3>(), uj = v.u[1].head<3>();
  EXPECT_NEAR(n.dot(ui - uj), approach, 1e-12 * approach);
  EXPECT_LT((ui - n.dot(ui) * n).norm(), 1e-12 * approach);
  EXPECT_LT(v.u[0].tail<3>().norm() + v.u[1].tail<3>().norm(), 1e-12 * approach);
  // The squeeze dominates: without it the spheres would approach at 2 F / zeta.
  EXPECT_LT(approach, 0.5 * 2.0 * force / (6.0 * kPi * a));
}

TEST(SphereForceBalance, SpherePressedOnAWallSphereIsAtRestAtTheOverlapFOverKn) {
  // A mobile sphere pressed by F against a fixed wall sphere along n: the contact spring holds
  // it at overlap F / kn (no flow), and at twice that overlap it moves back at the rate the drag
  // and the contact dashpot (lubrication frozen at h = 0) give.
  const double a = 0.5, kn = 1e4, force = 3.0;
  const Space3 n = Space3(0.3, 1.0, -0.4).normalized();
  const FrictionalContact contact{kn, 0.5 * kn, 0.5};
  const Lubrication lub{0.01, 0.5};
  for (const double factor : {1.0, 2.0}) {
    const double overlap = factor * force / kn;
    const Space3 xi(4.0, 4.0, 4.0);
    Particles3 p = spheres({xi, xi + (2.0 * a - overlap) * n}, {a, a});
    p.n_mobile = 1;
    p.motion[1] = Motion::FixedWall;
    Vec6 push = Vec6::Zero();
    push.head<3>() = force * n;
    p.external = {push, Vec6::Zero()};
    Box3 box = open_box(8.0);
    box.lees_edwards = false;
    NeighbourList3 list(lub.range_factor(), 0.3);
    list.rebuild(p, box);
    ForceBalance3::update_contacts(p, box, list.pairs());
    ASSERT_EQ(list.pairs().size(), 1u);
    ASSERT_TRUE(list.pairs()[0].history.touching);
    ForceBalance3 fb(lub, contact, 6, false);
    fb.on_rebuild(p, list.pairs());
    VelocitiesOf<Dim3> v;
    WallBodies walls;
    walls.bottom = {1};
    walls.top_role = WallRole::Fixed;
    ASSERT_TRUE(fb.solve(p, box, ImposedFlow{0.0, 0.0}, list.pairs(), 0.0, &walls, v));
    const double zeta = 6.0 * kPi * a, damping = lub.coefficients(a, a, 0.0).xa;
    const double expected = (force - kn * overlap) / (zeta + damping);
    EXPECT_NEAR(n.dot(v.u[0].head<3>()), expected, 1e-12 * force / zeta) << "overlap " << overlap;
  }
}

// ---- The disc engine as the restriction of the sphere engine to one plane ---------------------

using testing_3d::lift;

// (u_x, u_y, omega_z) of a sphere's velocity and the size of the rest (u_z, omega_x, omega_y).
Vec3 in_plane(const Vec6& u) {
  return {u[0], u[1], u[5]};
}
double out_of_plane(const Vec6& u) {
  return std::abs(u[2]) + std::abs(u[3]) + std::abs(u[4]);
}

class PlaneRestriction : public testing::TestWithParam<std::pair<std::string, IntegratorType>> {};

TEST_P(PlaneRestriction, SpheresInOnePlaneMoveAsTheDiscs) {
  const auto [scene, integrator] = GetParam();
  Config cfg;
  cfg.scene.type = scene;
  cfg.particles.n = 200;
  cfg.particles.phi_init = 0.78;
  cfg.flow.j = 1e-2;
  cfg.contact.ktilde = 1e4;
  cfg.integrator.type = integrator;
  Simulation sim(cfg);
  for (int s = 0; s < 30; ++s) sim.step();
  Dynamics& d = sim.dynamics();
  // Both lists from the same (wrapped) positions, so that they hold the same pairs.
  d.rebuild_now();
  d.begin_step();
  const bool implicit = sim.integrator().implicit_springs();
  const double dt = implicit ? sim.integrator().last_dt() : 0.0;

  // The same state in three dimensions, the plane half-way up a cell too deep for z images.
  const double lz = 40.0;
  Particles3 p = lift(d.particles(), 0.5 * lz);
  Box3 box;
  static_cast<Box&>(box) = d.box();
  box.lz = lz;
  const auto& pairs2 = d.neighbours().pairs();
  NeighbourList3 list(d.force_balance().laws().range_factor(), d.neighbours().skin());
  list.rebuild(p, box);
  ASSERT_EQ(list.pairs().size(), pairs2.size());
  // Each contact's history: the disc's spring xi along t = z x n is the sphere's vector xi t.
  std::map<std::pair<int, int>, const Pair*> by_key;
  for (const Pair& pr : pairs2) by_key[{pr.i, pr.j}] = &pr;
  int contacts = 0, sliding = 0;
  for (Pair3& pr : list.pairs()) {
    const Pair& p2 = *by_key.at({pr.i, pr.j});
    const Vec2 r2 = pair_separation(d.particles(), d.box(), p2);
    const Space3 r3 = pair_separation(p, box, pr);
    ASSERT_LT((Space3(r2.x(), r2.y(), 0.0) - r3).norm(), 1e-12);
    const Vec2 t = perp(r2.normalized());
    pr.history.touching = p2.history.touching;
    pr.history.contact.xi = p2.history.contact.xi * Space3(t.x(), t.y(), 0.0);
    pr.history.contact.sliding = p2.history.contact.sliding;
    contacts += p2.history.touching ? 1 : 0;
    sliding += p2.history.contact.sliding ? 1 : 0;
  }
  ASSERT_GT(contacts, 20) << "the test needs a packing with contacts";

  ForceBalance3 fb(d.force_balance().laws(), 6, implicit);
  fb.on_rebuild(p, list.pairs());
  Velocities v2;
  VelocitiesOf<Dim3> v3;
  ASSERT_TRUE(d.solve(dt, v2));
  ASSERT_TRUE(fb.solve(p, box, d.flow(), list.pairs(), dt, d.wall_bodies(), v3));

  // Both are direct solves of SPD systems to round-off (residual ~1e-15), with different
  // orderings: 1e-9 of the largest velocity leaves room for their conditioning, while a wrong
  // block or sign in 3D is O(1).
  const auto compare = [&](const char* what) {
    double scale = 0.0;
    for (const Vec3& u : v2.u) scale = std::max(scale, u.cwiseAbs().maxCoeff());
    ASSERT_GT(scale, 0.0);
    double worst = 0.0, off = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      worst = std::max(worst, (in_plane(v3.u[i]) - v2.u[i]).cwiseAbs().maxCoeff());
      off = std::max(off, out_of_plane(v3.u[i]));
    }
    EXPECT_LT(worst, 1e-9 * scale) << what;
    EXPECT_LT(off, 1e-12 * scale) << what;
    EXPECT_NEAR(v3.wall_v, v2.wall_v, 1e-9 * scale) << what;
  };
  compare("solve");

  if (implicit) {
    // Contacts that entered sliding and unload stick: the same ones in both, and the re-solve
    // on the old factor with low-rank terms (one per disc contact, two per sphere contact)
    // agrees again.
    std::vector<std::size_t> switched2, switched3;
    const int n2 = d.stick_reversed_sliding(v2, dt, &switched2);
    const int n3 = fb.stick_reversed_sliding(p, list.pairs(), v3.u, dt, &switched3);
    EXPECT_EQ(n2, n3);
    if (n2 > 0) {
      ASSERT_TRUE(d.resolve_with_sticking(dt, switched2, v2));
      ASSERT_TRUE(fb.resolve_with_sticking(p, box, d.flow(), list.pairs(), switched3, dt,
                                           d.wall_bodies(), v3));
      compare("re-solve with sticking contacts");
    }
    RecordProperty("sliding_contacts", sliding);
    RecordProperty("switched_contacts", n2);
  }
}

INSTANTIATE_TEST_SUITE_P(
    ScenesAndIntegrators, PlaneRestriction,
    testing::Values(std::make_pair(std::string("simple_shear"), IntegratorType::Implicit),
                    std::make_pair(std::string("simple_shear"), IntegratorType::Euler),
                    std::make_pair(std::string("pressure_shear"), IntegratorType::Implicit)),
    [](const auto& info) {
      return info.param.first + "_" + std::string(to_string(info.param.second));
    });

}  // namespace
}  // namespace sheardiff
