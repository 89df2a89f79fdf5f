// Stepping spheres (Dynamics3 and the integrators instantiated in three dimensions): a sphere
// pressed on a wall sphere settles at the overlap F / kn; a sphere sliding on one turns its
// friction with a turned load; spheres whose centres lie in one plane
// step exactly as the discs of the same configuration; and in a pressure cell of spheres between
// rough walls of frozen spheres, the suspension pushes on the floating top wall with exactly
// P Lx Lz at every step once the wall rests on it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/engine.hpp"
#include "sheardiff/integrator/integrators.hpp"
#include "sheardiff/integrator/stress.hpp"
#include "sheardiff/scene/scene.hpp"
#include "spheres_in_a_plane.hpp"

namespace sheardiff {
namespace {

Dynamics3 make_dynamics(const Config& cfg, Particles3 p, const Box3& box, const ImposedFlow& flow,
                        std::optional<WallBodies> walls, bool implicit) {
  ForceBalance3 fb(PairLaws::from(cfg), rotational_unknowns(cfg) ? 6 : 3, implicit);
  return Dynamics3(std::move(p), box, flow, std::move(fb),
                   NeighbourList3(interaction_range_factor(cfg), cfg.neighbour.skin),
                   step_limits(cfg, flow.clock_rate(), implicit), std::move(walls));
}

TEST(SphereDynamics, SpherePressedOnAWallSphereSettlesAtTheOverlapFOverKn) {
  Config cfg;
  cfg.contact.ktilde = 1e4;
  const double a = 0.5, force = 2.0;
  const Space3 n = Space3(-0.2, 1.0, 0.6).normalized();
  Particles3 p;
  p.resize(2);
  p.n_mobile = 1;
  p.position = {Space3(3.0, 3.0, 3.0), Space3(3.0, 3.0, 3.0) + 1.02 * n};
  p.unwrapped = p.position;
  p.radius = {a, a};
  p.motion[1] = Motion::FixedWall;
  Vec6 push = Vec6::Zero();
  push.head<3>() = force * n;
  p.external = {push, Vec6::Zero()};
  Box3 box;
  box.lx = box.ly = box.lz = 8.0;
  WallBodies walls;
  walls.bottom = {1};
  walls.top_role = WallRole::Fixed;
  for (const IntegratorType type : {IntegratorType::Implicit, IntegratorType::Euler}) {
    Dynamics3 d =
        make_dynamics(cfg, p, box, ImposedFlow{0.0, 0.0}, walls, type == IntegratorType::Implicit);
    auto integrator = make_integrator_of<Dim3>(type);
    // Without a flow nothing bounds an implicit step but its growth (1.25 per step): 50 steps
    // take it from the approach (dt ~ 0.03) to rest (dt ~ 50, thousands of the spring's
    // relaxation time (zeta + XA_0) / kn = 0.025). Explicit springs stay at their stability
    // limit: 3000 steps.
    const int steps = type == IntegratorType::Implicit ? 50 : 3000;
    for (int s = 0; s < steps; ++s) ASSERT_TRUE(integrator->step(d));
    const Space3 r = d.particles().position[1] - d.particles().position[0];
    // The rest state is exact: 1e-6 of the overlap is a settled contact, a wrong spring scale is
    // O(1).
    EXPECT_NEAR((2.0 * a - r.norm()) / (force / cfg.contact.ktilde), 1.0, 1e-6) << to_string(type);
    // Pressed along the line of centres, it neither slides off nor turns.
    EXPECT_LT((r.normalized() - n).norm(), 1e-9) << to_string(type);
    EXPECT_LT(d.particles().velocity[0].tail<3>().norm(), 1e-9) << to_string(type);
    // The pair stress of the one contact is -(r / V) n (x) F n: its normal components go as
    // n_a^2 (sigma_zz / sigma_xx = n_z^2 / n_x^2 = 9), and the pressure of spheres is the trace
    // over 3 (a disc's (xx + yy) / 2 would miss sigma_zz).
    const StressSample st = measure_stress(d, integrator->velocities(), 1.0);
    EXPECT_NEAR(st.szz / st.sxx, n.z() * n.z() / (n.x() * n.x()), 1e-6) << to_string(type);
    EXPECT_NEAR(st.syy / st.sxx, n.y() * n.y() / (n.x() * n.x()), 1e-6) << to_string(type);
    EXPECT_DOUBLE_EQ(st.pressure(), -(st.sxx + st.syy + st.szz) / 3.0) << to_string(type);
    // And its size is r F / (3 V), V = Lx H Lz (this test's H, the top "wall" being empty, is
    // a signed placeholder: compared in magnitude).
    const double volume = std::abs(box.lx * box.lz * d.height());
    EXPECT_NEAR(std::abs(st.pressure()) * 3.0 * volume / (r.norm() * force), 1.0, 1e-6)
        << to_string(type);
  }
}

// A sphere sliding on a wall sphere under a tangential load 1.5 times the Coulomb cap, at a
// large implicit step (tens of caps of slip a step), after the load turns by 30 degrees in the
// tangent plane. The law (continuous in time): the friction force turns with the slip, within a
// fraction of a step here, to lie against the load. The load direction is carried with the pair
// as the spring is (projected on the new tangent plane), so the target does not move. The first
// step after the turn brings the force within ~0.01 rad of the load either way. With
// contact.sliding_stiffness = "sideways" the rest goes by a factor ~30 a step, to round-off
// within ten steps, and the contact ends every step sliding. With "none" the direction is explicit:
// each step turns it to the last step's slip, and with a load below twice the cap that
// correction overshoots, 7-10 times the error, until the slip reverses and the contact sticks;
// it cycles so (three steps, up to 0.94 rad) and never settles.
struct TurnedLoadRun {
  std::vector<double> angle;  // signed angle of -xi from the load about n, after each step
  long stuck = 0;             // contacts switched to sticking after the turn
  int sliding_steps = 0;      // steps after the turn that ended sliding
};

TurnedLoadRun slide_with_turned_load(const std::string& sliding_stiffness) {
  Config cfg;
  cfg.contact.ktilde = 1e4;
  cfg.contact.sliding_stiffness = sliding_stiffness;
  cfg.integrator.dt = 0.1;
  cfg.neighbour.skin = 1.0;  // no rebuild: the pair's history is read after each step
  const double a = 0.5, fn = 2.0, ft = 1.5 * cfg.contact.mu * fn;
  Particles3 p;
  p.resize(2);
  p.n_mobile = 1;
  p.position = {Space3(4.0, 4.0, 4.0), Space3(4.0, 5.0 - fn / cfg.contact.ktilde, 4.0)};
  p.unwrapped = p.position;
  p.radius = {a, a};
  p.motion[1] = Motion::FixedWall;
  Box3 box;
  box.lx = box.ly = box.lz = 8.0;
  WallBodies walls;
  walls.bottom = {1};
  walls.top_role = WallRole::Fixed;
  Dynamics3 d = make_dynamics(cfg, p, box, ImposedFlow{0.0, 0.0}, walls, true);
  auto integrator = make_integrator_of<Dim3>(IntegratorType::Implicit);
  Space3 load = Space3::UnitX();
  TurnedLoadRun run;
  for (int s = 0; s < 40; ++s) {
    const Space3 r = d.particles().position[1] - d.particles().position[0];
    const Space3 n = r.normalized();
    if (s == 10) load = Eigen::AngleAxisd(kPi / 6.0, n) * load;  // the turn
    load = (load - load.dot(n) * n).normalized();                // carried with the pair
    Vec6 push = Vec6::Zero();
    push.head<3>() = fn * n + ft * load;
    d.particles_mut().external = {push, Vec6::Zero()};
    const long stuck_before = d.force_balance().sticking_counts().switched;
    EXPECT_TRUE(integrator->step(d));
    const auto& pairs = d.neighbours().pairs();
    EXPECT_EQ(pairs.size(), 1u);
    EXPECT_TRUE(pairs[0].history.touching) << "step " << s;
    if (s < 10) continue;
    const auto& spring = pairs[0].history.contact;
    run.stuck += d.force_balance().sticking_counts().switched - stuck_before;
    run.sliding_steps += spring.sliding ? 1 : 0;
    const Space3 n_end = (d.particles().position[1] - d.particles().position[0]).normalized();
    const Space3 f = -spring.xi.normalized();
    const Space3 l = (load - load.dot(n_end) * n_end).normalized();
    run.angle.push_back(std::atan2(l.cross(f).dot(n_end), l.dot(f)));
  }
  return run;
}

TEST(SphereDynamics, SlidingSphereFrictionTurnsWithItsLoad) {
  const TurnedLoadRun sideways = slide_with_turned_load("sideways");
  ASSERT_EQ(sideways.angle.size(), 30u);
  ASSERT_GT(std::abs(sideways.angle[0]), 1e-3) << "the turn is not seen";
  // Round-off of a direction is 1e-15 rad; 1e-12 is far below the first steps' errors.
  for (std::size_t k = 10; k < sideways.angle.size(); ++k)
    EXPECT_LT(std::abs(sideways.angle[k]), 1e-12) << "step " << k << " after the turn";
  // The step that sticks the contact once (its slip turned back) still narrows the angle; from
  // there it shrinks by more than 10x a step (25-40x here).
  EXPECT_LT(std::abs(sideways.angle[1]), std::abs(sideways.angle[0]));
  for (std::size_t k = 2; k < 10; ++k)
    EXPECT_LT(std::abs(sideways.angle[k]), 0.1 * std::abs(sideways.angle[k - 1]) + 1e-14)
        << "step " << k << " after the turn";
  EXPECT_LE(sideways.stuck, 1);
  EXPECT_EQ(sideways.sliding_steps, 30);

  const TurnedLoadRun none = slide_with_turned_load("none");
  double late = 0.0;
  for (std::size_t k = 15; k < none.angle.size(); ++k)
    late = std::max(late, std::abs(none.angle[k]));
  EXPECT_GT(late, 0.5) << "the explicit direction settled";
  EXPECT_GE(none.stuck, 5) << "the explicit direction did not reverse the slip";
}

using testing_3d::lift;

TEST(SphereDynamics, SpheresInOnePlaneStepAsTheDiscs) {
  // Forty implicit steps of a sheared dense packing from its start (no contact history yet) in
  // two and three dimensions: the same step sizes and, to round-off grown over the steps, the
  // same positions, contacts opening and springs loading alike; the spheres never leave their
  // plane. With either stick rule (contact.stick_rule): in the plane they are one test. And with
  // either stiffness of sliding spheres (contact.sliding_stiffness): across a stretch in the
  // plane is out of it, where nothing moves.
  for (const auto& [rule, sliding] : {std::pair{"unloading", "none"}, std::pair{"coulomb", "none"},
                                      std::pair{"unloading", "sideways"}}) {
    SCOPED_TRACE(std::string(rule) + ", " + sliding);
    Config cfg;
    cfg.particles.n = 200;
    cfg.particles.phi_init = 0.78;
    cfg.flow.j = 1e-2;
    cfg.contact.ktilde = 1e4;
    cfg.contact.stick_rule = rule;
    cfg.contact.sliding_stiffness = sliding;
    Simulation sim(cfg);
    Dynamics& d2 = sim.dynamics();
    const double lz = 40.0;
    Box3 box;
    static_cast<Box&>(box) = d2.box();
    box.lz = lz;
    Dynamics3 d3 =
        make_dynamics(cfg, lift(d2.particles(), 0.5 * lz), box, d2.flow(), std::nullopt, true);
    ASSERT_EQ(d3.neighbours().pairs().size(), d2.neighbours().pairs().size());
    auto i2 = make_integrator(IntegratorType::Implicit);
    auto i3 = make_integrator_of<Dim3>(IntegratorType::Implicit);
    for (int s = 0; s < 40; ++s) {
      ASSERT_TRUE(i2->step(d2));
      ASSERT_TRUE(i3->step(d3));
      EXPECT_NEAR(i3->last_dt(), i2->last_dt(), 1e-9 * i2->last_dt()) << "step " << s;
    }
    int contacts = 0, loaded = 0;
    for (const Pair& pr : d2.neighbours().pairs()) {
      contacts += pr.history.touching ? 1 : 0;
      loaded += pr.history.contact.xi != 0.0 ? 1 : 0;
    }
    ASSERT_GT(contacts, 20) << "the test needs a packing with contacts";
    ASSERT_GT(loaded, 10) << "the test needs loaded tangential springs";
    double worst = 0.0, off = 0.0;
    for (std::size_t i = 0; i < d2.particles().size(); ++i) {
      const Space3& x3 = d3.particles().unwrapped[i];
      const Vec2& x2 = d2.particles().unwrapped[i];
      worst = std::max(worst, (Vec2(x3.x(), x3.y()) - x2).norm());
      off = std::max(off, std::abs(x3.z() - 0.5 * lz));
    }
    // Positions of order 10 d after 40 steps of ~1e-3 d: round-off of the solves (1e-13 relative)
    // grows little over so few steps; 1e-9 d is far below a step and far above round-off.
    EXPECT_LT(worst, 1e-9);
    EXPECT_LT(off, 1e-12);
  }
}

// The pressure cell of spheres (scene/pressure_shear_3d.cpp) at J = 1e-2, ktilde = 1e4, with
// implicit springs: 48 spheres, 4 x 4 x 3 on the loose lattice, between walls of 6 x 6 spheres.
struct SphereCell {
  Config cfg;
  Scene3 scene;
  Dynamics3 dynamics;
  std::unique_ptr<IntegratorOf<Dim3>> integrator;

  explicit SphereCell(std::int64_t seed, const std::string& sliding_stiffness = "none")
      : cfg(cell_config(seed, sliding_stiffness)),
        scene(build_pressure_shear_3d(cfg)),
        dynamics(make_dynamics(cfg, scene.particles, scene.box, scene.flow, scene.walls, true)),
        integrator(make_integrator_of<Dim3>(IntegratorType::Implicit)) {}

  static Config cell_config(std::int64_t seed, const std::string& sliding_stiffness) {
    Config c;
    c.contact.sliding_stiffness = sliding_stiffness;
    c.particles.n = 48;
    c.particles.phi_init_spheres = 0.0;  // the loose lattice
    c.flow.j = 1e-2;
    c.contact.ktilde = 1e4;
    c.run.seed = seed;
    return c;
  }
};

TEST(SphereDynamics, PressureCellWallForceEqualsPLxLzEveryStep) {
  SphereCell cell(11);
  Dynamics3& d = cell.dynamics;
  auto& integrator = cell.integrator;
  // The top wall falls onto the packing, which compacts under it until its contacts carry the
  // load (on average one contact per sphere or more, the wall held for 200 steps).
  const auto n_mobile = static_cast<int>(d.particles().n_mobile);
  int held = 0, contacts = 0, s = 0;
  for (; s < 40000 && (held < 200 || contacts < n_mobile); ++s) {
    ASSERT_TRUE(integrator->step(d));
    held = integrator->velocities().wall_free_fall ? 0 : held + 1;
    contacts = integrator->sample(d, 1.0).contacts;
  }
  ASSERT_TRUE(held >= 200 && contacts >= n_mobile)
      << "the packing did not come to carry the wall: " << contacts << " contacts after " << s
      << " steps";
  RecordProperty("compaction_steps", s);
  const double load = d.box().lx * d.box().lz;
  for (s = 0; s < 100; ++s) {
    ASSERT_TRUE(integrator->step(d));
    ASSERT_FALSE(integrator->velocities().wall_free_fall) << "step " << s;
    const StressSample sample = integrator->sample(d, 1.0);
    // The wall's y balance is one row of the solved system: round-off only.
    ASSERT_NEAR(sample.top_wall_fy / load, 1.0, 1e-9) << "step " << s;
  }
  // The suspension is sheared: the top wall moves at gammadot times its height in x (taken at
  // the start of the step; the wall has moved by V dt in y since).
  EXPECT_NEAR(d.wall_bodies()->driven_vx / (cell.cfg.flow.j * d.height()), 1.0, 1e-3);
}

void expect_resolve_equals_fresh_solve(const std::string& sliding_stiffness) {
  SphereCell cell(5, sliding_stiffness);
  Dynamics3& d = cell.dynamics;
  auto& integrator = cell.integrator;
  std::vector<std::size_t> switched;
  bool checked[2] = {false, false};  // [with a floating-wall contact]
  for (int s = 0; s < 40000 && !(checked[0] && checked[1]); ++s) {
    ASSERT_TRUE(integrator->step(d));
    if (s < 500) continue;
    const double dt = integrator->last_dt();
    d.begin_step();
    VelocitiesOf<Dim3> low_rank, fresh;
    ASSERT_TRUE(d.solve(dt, low_rank));
    if (d.stick_reversed_sliding(low_rank, dt, &switched) == 0) continue;
    bool wall = false;
    for (std::size_t k : switched)
      wall = wall || d.particles().motion[d.neighbours().pairs()[k].j] == Motion::FloatingWall;
    const long before = d.force_balance().sticking_counts().low_rank;
    ASSERT_TRUE(d.resolve_with_sticking(dt, switched, low_rank));
    // Over the budget (many switched at once) it refactorises: not the path under test.
    if (d.force_balance().sticking_counts().low_rank != before + 1) continue;
    ASSERT_TRUE(d.solve(dt, fresh));
    double scale = 0.0, worst = 0.0;
    for (std::size_t i = 0; i < d.particles().n_mobile; ++i) {
      scale = std::max(scale, fresh.u[i].cwiseAbs().maxCoeff());
      worst = std::max(worst, (low_rank.u[i] - fresh.u[i]).cwiseAbs().maxCoeff());
    }
    // Woodbury on a well-conditioned factor: round-off; a missing row is O(1) on the contact.
    EXPECT_LT(worst, 1e-9 * scale) << switched.size() << " contacts switched at step " << s
                                   << (wall ? ", the floating wall's among them" : "");
    EXPECT_NEAR(low_rank.wall_v, fresh.wall_v, 1e-9 * scale) << "step " << s;
    checked[wall] = true;
  }
  EXPECT_TRUE(checked[0]) << "no sliding contact between spheres stuck";
  EXPECT_TRUE(checked[1]) << "no sliding contact with the floating wall stuck";
}

TEST(SphereDynamics, StickingReSolveOnTheOldFactorEqualsAFreshSolve) {
  // Implicit springs: a sliding contact whose solved slip unloads its spring sticks, and the step
  // is solved again with its tangential stiffness dt kt W^T W added as low-rank terms on the old
  // factor (a contact with the floating wall also changes the wall's border of the system). A
  // fresh assembly and factorisation with those contacts sticking must give the same
  // velocities. Found in the sheared pressure cell of spheres, once with only particle pairs
  // switched and once with a floating-wall contact among them; and with sliding springs stiff
  // across their stretch (contact.sliding_stiffness), whose terms are the row along it and the
  // rest of the row across.
  for (const char* sliding : {"none", "sideways"}) {
    SCOPED_TRACE(sliding);
    expect_resolve_equals_fresh_solve(sliding);
  }
}

}  // namespace
}  // namespace sheardiff
