// Two-body tests of the pair laws through the whole engine (Simulation -> Dynamics ->
// ForceBalance -> integrator): squeeze flow against an analytic ODE, the static overlap of a
// loaded contact, Coulomb friction (sliding and sticking) and the reset of the tangential spring.
//
// Units of docs/model.md: d = 1 (small diameter), eta = 1, P = 1. The scenes are two discs in the
// middle of a 20 x 20 Lees-Edwards cell with gammadot = 0 (quiescent fluid), so no periodic image
// is ever within the neighbour cut-off (s (1 + h_max/2) + skin < 3 << 20).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

#include "sheardiff/run.hpp"

namespace sheardiff {
namespace {

constexpr double kDelta = 0.01;  // lubrication regularisation (Config default, docs/model.md s. 4)

Config two_body_config(IntegratorType type, double dt, double ktilde) {
  Config cfg;
  cfg.flow.j = 0.0;  // quiescent fluid; nothing in Simulation divides by it with a fixed dt
  cfg.contact.ktilde = ktilde;
  cfg.contact.kt_ratio = 0.5;
  cfg.contact.mu = 0.5;
  cfg.lubrication.enabled = true;
  cfg.lubrication.delta = kDelta;
  cfg.lubrication.h_max = 0.5;
  cfg.integrator.type = type;
  cfg.integrator.dt = dt;  // fixed step
  // A wide skin: the two discs never move far enough to rebuild the list, so the PairTerm
  // geometry read after a step is the one the step used (a rebuild resets the terms).
  cfg.neighbour.skin = 1.0;
  return cfg;
}

// Two discs of radii ai (left, index 0) and aj (right, index 1) on a horizontal line through the
// cell centre, at reduced gap h (negative = overlap), i.e. centre distance r = s (1 + h/2).
Scene two_body_scene(double ai, double aj, double h) {
  Scene sc;
  sc.particles.resize(2);
  sc.particles.n_mobile = 2;
  const double r = (ai + aj) * (1.0 + 0.5 * h);
  sc.particles.position[0] = Vec2(10.0 - 0.5 * r, 10.0);
  sc.particles.position[1] = Vec2(10.0 + 0.5 * r, 10.0);
  sc.particles.unwrapped = sc.particles.position;
  sc.particles.radius = {ai, aj};
  sc.particles.species = {ai > 0.5 + 1e-9 ? 1 : 0, aj > 0.5 + 1e-9 ? 1 : 0};
  sc.box.lx = 20.0;
  sc.box.ly = 20.0;
  sc.box.lees_edwards = true;
  sc.flow.gammadot = 0.0;
  sc.flow.y0 = 0.0;
  return sc;
}

PairGeometry geometry(const Simulation& sim) {
  const Particles& p = sim.dynamics().particles();
  return PairGeometry::make(p.position[1] - p.position[0], p.radius[0], p.radius[1]);
}

// ---------------------------------------------------------------------------------------------
// 1. Squeeze flow.
//
// External force +F n on disc i and -F n on disc j (n from i to j). Only the squeeze mode is
// excited: t.du = 0 and no torque, so the shear/rotation couplings vanish and omega = 0. With
// u_i = v_i n, u_j = -v_j n and w = v_i + v_j the closing speed, force balance on each disc is
//   F = zeta_i v_i + XA w = zeta_j v_j + XA w,      zeta_k = 3 pi d_k,
// so w = F m / (1 + XA m) with m = 1/zeta_i + 1/zeta_j (equal discs: w = 2F/(zeta + 2 XA), i.e.
// v = F/(zeta + 2 XA) as in the brief), and since h = 2r/s - 2,  dh/dt = -(2/s) w.
// XA = 6 pi * 2 a_i^2 a_j^2 / s^3 / (h + delta)  (docs/model.md section 4, written out here
// independently of Lubrication::coefficients).
struct SqueezeOde {
  double ai, aj, force;
  double rate(double h) const {
    const double s = ai + aj;
    const double xa = 6.0 * kPi * 2.0 * ai * ai * aj * aj / (s * s * s) / (h + kDelta);
    const double m = 1.0 / (3.0 * kPi * 2.0 * ai) + 1.0 / (3.0 * kPi * 2.0 * aj);
    return -(2.0 / s) * force * m / (1.0 + xa * m);
  }
  // Classical RK4 from t0 to t1 with steps <= 1e-4: the local rate |d rate/dh| <= 1 (see below)
  // makes its error ~ (1e-4)^4 per unit time, far below anything asserted.
  double advance(double h, double t0, double t1) const {
    const int n = std::max(1, static_cast<int>(std::ceil((t1 - t0) / 1e-4)));
    const double k = (t1 - t0) / n;
    for (int i = 0; i < n; ++i) {
      const double k1 = rate(h), k2 = rate(h + 0.5 * k * k1), k3 = rate(h + 0.5 * k * k2),
                   k4 = rate(h + k * k3);
      h += k / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    return h;
  }
};

struct SqueezeResult {
  double max_rel_error = 0.0;  // max over checkpoints of |h_sim - h_ode| / h_ode
  double final_gap = 0.0;
  int checkpoints = 0;
};

// Runs the squeeze to time t_end (a whole number of steps) and compares the gap with the ODE
// every `every` steps.
SqueezeResult run_squeeze(double ai, double aj, IntegratorType type, double dt, double t_end,
                          int every) {
  constexpr double kF = 1.0, kH0 = 0.3;
  Simulation sim(two_body_config(type, dt, 1e4), two_body_scene(ai, aj, kH0));
  sim.dynamics().particles_mut().external = {Vec3(kF, 0.0, 0.0), Vec3(-kF, 0.0, 0.0)};
  const SqueezeOde ode{ai, aj, kF};
  const int steps = static_cast<int>(std::lround(t_end / dt));
  SqueezeResult res;
  double h_ref = kH0, t_ref = 0.0;
  for (int k = 1; k <= steps; ++k) {
    sim.step();
    if (k % every != 0 && k != steps) continue;
    const double t = sim.dynamics().time();
    h_ref = ode.advance(h_ref, t_ref, t);
    t_ref = t;
    const PairGeometry g = geometry(sim);
    res.max_rel_error = std::max(res.max_rel_error, std::abs(g.h - h_ref) / h_ref);
    res.final_gap = g.h;
    ++res.checkpoints;
    // The discs stay on their line of centres and never touch (no contact forces involved).
    EXPECT_NEAR(g.n.y(), 0.0, 1e-12);
    EXPECT_FALSE(sim.dynamics().neighbours().pairs().at(0).history.touching);
  }
  return res;
}

// Time to close from h = 0.3 to h ~ 0.018 (0.5/0.5) or 0.023 (0.5/0.7) for F = 1. Near contact (h +
// delta) decays exponentially with rate lambda = (2/s) F / (6 pi 2 a_i^2 a_j^2 / s^3) (the
// XA-dominated limit of -d rate/dh): 0.849 for 0.5/0.5 and 0.624 for 0.5/0.7, and |d rate/dh| <=
// lambda everywhere.
constexpr double kSqueezeTimeEqual = 3.5;
constexpr double kSqueezeTimeUnequal = 4.5;

// Heun is second order: the global error of a linear decay y' = -lambda y over time T is
// ~ lambda^3 dt^2 T / 6 relative, i.e. ~ 0.61 * 1e-6 * 3.5 / 6 = 3.6e-7 for dt = 1e-3. In h
// (rather than h + delta) that is at most (h + delta)/h <= 1.6 times larger because we stop at
// h >= 0.017. The bound 1e-5 leaves a factor > 15 for the nonlinearity of the rate (measured:
// 2.9e-7 for 0.5/0.5, 1.3e-7 for 0.5/0.7).
TEST(TwoBodySqueeze, HeunFollowsAnalyticOdeEqualSpheres) {
  const SqueezeResult r = run_squeeze(0.5, 0.5, IntegratorType::Heun, 1e-3, kSqueezeTimeEqual, 250);
  EXPECT_GE(r.checkpoints, 14);
  // The run covers the lubrication-dominated regime (rate ~ 1/XA) but stops before contact.
  EXPECT_LT(r.final_gap, 0.04);
  EXPECT_GT(r.final_gap, 0.01);
  EXPECT_LT(r.max_rel_error, 1e-5);
}

TEST(TwoBodySqueeze, HeunFollowsAnalyticOdeUnequalSpheres) {
  // a = 0.5 and 0.7: XA = 6 pi * 2 (0.25 * 0.49) / 1.2^3 / (h + delta) = 2.672 / (h + delta),
  // drags 3 pi and 4.2 pi. lambda = 0.624, T = 4.5: error estimate 0.24e-6 * 4.5 / 6 ~ 2e-7.
  const SqueezeResult r =
      run_squeeze(0.5, 0.7, IntegratorType::Heun, 1e-3, kSqueezeTimeUnequal, 250);
  EXPECT_GE(r.checkpoints, 18);
  EXPECT_LT(r.final_gap, 0.04);
  EXPECT_GT(r.final_gap, 0.01);
  EXPECT_LT(r.max_rel_error, 1e-5);
}

// Explicit Euler (and the implicit-spring integrator, which without contacts solves exactly the
// same system with the start-of-step geometry) is first order: global relative error
// ~ lambda^2 dt T / 2 = 0.72 * 1e-3 * 3.5 / 2 = 1.3e-3 in (h + delta), <= 1.6x that in h
// (measured: 1.24e-3).
TEST(TwoBodySqueeze, FirstOrderIntegratorsFollowAnalyticOde) {
  for (IntegratorType type : {IntegratorType::Euler, IntegratorType::Implicit}) {
    SCOPED_TRACE(to_string(type));
    const SqueezeResult r = run_squeeze(0.5, 0.5, type, 1e-3, kSqueezeTimeEqual, 250);
    EXPECT_LT(r.max_rel_error, 3e-3);
    // ... and not accidentally much better: a first-order method must show an O(dt) error.
    EXPECT_GT(r.max_rel_error, 1e-4);
  }
}

// Convergence orders: halving dt divides the error by 4 (Heun) and by 2 (Euler). Measured at a
// fixed time (T = 3, h ~ 0.03) with dt = 0.02 / 0.01 (lambda dt <= 0.017: asymptotic regime, so
// the ratios are within a few percent of 4 and 2; the windows allow 12%).
TEST(TwoBodySqueeze, ConvergenceOrders) {
  const double t = 3.0;
  const double heun1 = run_squeeze(0.5, 0.7, IntegratorType::Heun, 0.02, t, 1000000).max_rel_error;
  const double heun2 = run_squeeze(0.5, 0.7, IntegratorType::Heun, 0.01, t, 1000000).max_rel_error;
  const double euler1 =
      run_squeeze(0.5, 0.7, IntegratorType::Euler, 0.02, t, 1000000).max_rel_error;
  const double euler2 =
      run_squeeze(0.5, 0.7, IntegratorType::Euler, 0.01, t, 1000000).max_rel_error;
  EXPECT_NEAR(heun1 / heun2, 4.0, 0.5) << heun1 << " " << heun2;
  EXPECT_NEAR(euler1 / euler2, 2.0, 0.25) << euler1 << " " << euler2;
}

// ---------------------------------------------------------------------------------------------
// 2. Static overlap under a steady load.
//
// Discs start at a small gap h = 0.02 and are pressed together by F = 1 along the line of
// centres. At steady state nothing moves (U = 0 solves the force balance exactly once the spring
// balances the load: the drag, lubrication and dashpot forces are all proportional to U), so
//   kn * overlap = F   exactly, overlap = F / kn.
// Relaxation: closing the gap takes ~ ln(3)/0.85 ~ 1.3 time units; in contact the normal mode
// relaxes at lambda = 2 kn / (zeta + 2 XA(0)) = kn / 240 >= 4.2 per unit time (kn >= 1e3). The
// implicit scheme damps it by 1/(1 + lambda dt) per step and Heun (lambda dt <= 0.42, inside its
// stability region; the stiffer tangential modes are never excited: by symmetry the slip and xi
// stay exactly 0) by 1 - lambda dt + (lambda dt)^2/2; after 1500 steps of dt = 0.01 the
// transient is < e^-40, so the overlap must match F/kn to round-off; 1e-6 relative is generous.
TEST(TwoBodyContact, SteadyOverlapIsForceOverStiffness) {
  constexpr double kF = 1.0;
  for (IntegratorType type : {IntegratorType::Implicit, IntegratorType::Heun}) {
    double overlap_1e3 = 0.0, overlap_1e4 = 0.0;
    for (double kn : {1e3, 1e4}) {
      SCOPED_TRACE(std::string(to_string(type)) + " kn=" + std::to_string(kn));
      Simulation sim(two_body_config(type, 0.01, kn), two_body_scene(0.5, 0.5, 0.02));
      sim.dynamics().particles_mut().external = {Vec3(kF, 0.0, 0.0), Vec3(-kF, 0.0, 0.0)};
      for (int k = 0; k < 1500; ++k) sim.step();
      const Pair& pr = sim.dynamics().neighbours().pairs().at(0);
      EXPECT_TRUE(pr.history.touching);
      const double overlap = geometry(sim).overlap();
      EXPECT_NEAR(overlap * kn / kF, 1.0, 1e-6) << "overlap " << overlap;
      // Static: the solved velocities vanish (scale: F/zeta ~ 0.1 when free).
      for (const Vec3& u : sim.integrator().velocities().u) EXPECT_LT(u.norm(), 1e-8);
      // No tangential load: the spring is never stretched.
      EXPECT_NEAR(pr.history.contact.xi, 0.0, 1e-15);
      (kn == 1e3 ? overlap_1e3 : overlap_1e4) = overlap;
    }
    // overlap ~ 1/k
    EXPECT_NEAR(overlap_1e3 / overlap_1e4, 10.0, 1e-5);
  }
}

// The adaptive step of two equal discs closing head on at speed w = 1 from a gap g = 0.001 d (no
// contact yet): the gap limit allows a closing of max_gap_fraction (g + delta s / 2) = 0.003 d,
// i.e. an overlap of 0.002 d after the step; integrator.max_entry_overlap = 2e-4 d caps the
// closing at g + 2e-4 = 0.0012 d. The displacement limit (0.1 d / 0.5) stays out of the way.
TEST(TwoBodyContact, EntryOverlapLimitsTheStepThatCloses) {
  for (double entry : {0.0, 2e-4}) {
    SCOPED_TRACE("max_entry_overlap=" + std::to_string(entry));
    Config cfg = two_body_config(IntegratorType::Implicit, 0.0, 1e4);
    cfg.integrator.max_displacement = 0.1;
    cfg.integrator.max_entry_overlap = entry;
    Simulation sim(cfg, two_body_scene(0.5, 0.5, 0.002));
    Dynamics& d = sim.dynamics();
    d.begin_step();
    Velocities v;
    ASSERT_TRUE(d.solve(0.0, v));  // evaluates the pair's terms at this geometry
    ASSERT_FALSE(d.neighbours().pairs().at(0).history.touching);
    v.u[0] = Vec3(0.5, 0.0, 0.0);
    v.u[1] = Vec3(-0.5, 0.0, 0.0);
    StepLimit why = StepLimit::Fixed;
    const double dt = d.dt_limit(v, &why);
    EXPECT_EQ(why, StepLimit::Gap);
    EXPECT_NEAR(dt, entry > 0.0 ? 0.001 + entry : 0.5 * (0.001 + 0.5 * kDelta), 1e-12);
  }
}

// ---------------------------------------------------------------------------------------------
// 3. Coulomb friction.
//
// A single tangential force on one disc mostly rolls or translates the pair (rigid motions do
// not stretch the spring), so the tangential load is applied as a pure "shearing" of the contact:
// the generalised load that the spring alone can balance. With the spring law of docs/model.md
// (F_i = kt xi t, T_i = a_i kt xi, F_j = -F_i, T_j = a_j kt xi) the external load
//   on i: fn n - ft t, torque -ft a_i;    on j: -fn n + ft t, torque -ft a_j
// is in static equilibrium (U = 0) exactly when kn overlap = fn and kt xi = ft. Coulomb allows
// this only if ft <= mu fn: above it the contact must slide with kt |xi| = mu kn overlap.
// The load is re-aligned with the current line of centres before every step.
void set_contact_load(Simulation& sim, double fn, double ft) {
  Particles& p = sim.dynamics().particles_mut();
  const PairGeometry g =
      PairGeometry::make(p.position[1] - p.position[0], p.radius[0], p.radius[1]);
  const Vec2 fi = fn * g.n - ft * g.t;
  p.external = {Vec3(fi.x(), fi.y(), -ft * g.ai), Vec3(-fi.x(), -fi.y(), -ft * g.aj)};
}

struct ContactParams {
  double kn, kt, mu;
};
ContactParams params_of(const Config& cfg) {
  return {cfg.contact.ktilde, cfg.contact.kt_ratio * cfg.contact.ktilde, cfg.contact.mu};
}

// kt |xi| <= mu kn overlap for the active contact, at the configuration where the spring force
// is next evaluated (the end of the step, where xi is capped; no neighbour rebuild happens in
// these runs, checked by the callers). Returns kt |xi| / (mu kn overlap).
double coulomb_ratio(const Simulation& sim, const ContactParams& c) {
  const Pair& pr = sim.dynamics().neighbours().pairs().at(0);
  if (!pr.history.touching) return 0.0;
  const double limit = c.mu * c.kn * std::max(geometry(sim).overlap(), 0.0);
  EXPECT_LE(c.kt * std::abs(pr.history.contact.xi), limit * (1.0 + 1e-9))
      << "step " << sim.dynamics().steps() << " xi " << pr.history.contact.xi;
  return limit > 0.0 ? c.kt * std::abs(pr.history.contact.xi) / limit : 0.0;
}

// Sliding speed. At the cap kt xi = mu kn overlap, so the generalised force left on the pair is
// g = (fn - kn overlap) m - (ft - mu kn overlap) w, with m = (n, 0, -n, 0) and w = (t, a_i, -t,
// a_j). For equal discs the resistance A = drag + R_pair(h = 0) maps the antisymmetric-tangential
// and rotational subspace (which holds w) onto itself and never mixes it with m (A w has no n
// component), so the implicit normal stiffness dt kn m m^T does not enter and the slip rate
// v_s = -w.U is  v_s = (ft - mu kn overlap) w^T A^-1 w.  A is written out from docs/model.md s. 3-5
// (dashpots = lubrication at h = 0: Ln = 1/delta, Lt = ln(1/delta)).
double slip_mobility(const PairGeometry& g) {
  const double ai = g.ai, aj = g.aj, s = ai + aj, c = 6.0 * kPi;
  const double ln = 1.0 / kDelta, lt = std::log(1.0 / kDelta);
  const double xa = c * 2.0 * ai * ai * aj * aj / (s * s * s) * ln;
  const double ya =
      c * (4.0 / 15.0) * ai * aj * (2 * ai * ai + ai * aj + 2 * aj * aj) / (s * s * s) * lt;
  const double bi = c * (2.0 / 15.0) * ai * ai * aj * (4 * ai + aj) / (s * s) * lt;
  const double bj = c * (2.0 / 15.0) * ai * aj * aj * (ai + 4 * aj) / (s * s) * lt;
  const double gii = c * (8.0 / 15.0) * ai * ai * ai * aj / s * lt;
  const double gjj = c * (8.0 / 15.0) * ai * aj * aj * aj / s * lt;
  const double gij = c * (2.0 / 15.0) * ai * ai * aj * aj / s * lt;
  const Mat2 a = xa * g.n * g.n.transpose() + ya * g.t * g.t.transpose();
  Mat6 r = Mat6::Zero();
  r.block<2, 2>(0, 0) = a;
  r.block<2, 2>(0, 3) = -a;
  r.block<2, 2>(3, 0) = -a;
  r.block<2, 2>(3, 3) = a;
  r.block<2, 1>(0, 2) = bi * g.t;
  r.block<2, 1>(0, 5) = bj * g.t;
  r.block<2, 1>(3, 2) = -bi * g.t;
  r.block<2, 1>(3, 5) = -bj * g.t;
  r.block<1, 2>(2, 0) = bi * g.t.transpose();
  r.block<1, 2>(2, 3) = -bi * g.t.transpose();
  r.block<1, 2>(5, 0) = bj * g.t.transpose();
  r.block<1, 2>(5, 3) = -bj * g.t.transpose();
  r(2, 2) = gii;
  r(2, 5) = gij;
  r(5, 2) = gij;
  r(5, 5) = gjj;
  const double di = 2 * ai, dj = 2 * aj;
  Vec6 drag;
  drag << 3 * kPi * di, 3 * kPi * di, kPi * di * di * di, 3 * kPi * dj, 3 * kPi * dj,
      kPi * dj * dj * dj;
  r += drag.asDiagonal().toDenseMatrix();
  Vec6 w;
  w << g.t, ai, -g.t, aj;
  return w.dot(r.ldlt().solve(w));
}

// A sliding run: fn(t) = 1 + fn_rate t, ft = 0.8 > mu fn (fn <= 1.06 here), starting
// pre-compressed at the static overlap fn / kn (h = -2 overlap / s). Checks the Coulomb bound after
// every step and records the last step.
struct SlidingRun {
  int steps = 0, at_limit = 0;
  double ratio = 0.0;  // kt |xi| / (mu kn overlap) after the last step
  double xi = 0.0;
  double slip = 0.0;           // slip rate of the last step's velocities
  double expected_slip = 0.0;  // (ft - mu kn overlap) w^T A^-1 w at the last step's geometry
  double fn = 0.0, overlap = 0.0;
  bool rebuilt = false;
};

SlidingRun run_sliding(IntegratorType type, double fn_rate) {
  constexpr double kFt = 0.8;
  const Config cfg = two_body_config(type, 1e-3, 1e3);
  const ContactParams c = params_of(cfg);
  Simulation sim(cfg, two_body_scene(0.5, 0.5, -2.0 / c.kn));
  const std::size_t rebuilds = sim.dynamics().neighbours().rebuilds();
  SlidingRun run;
  run.steps = 3000;
  for (int k = 0; k < run.steps; ++k) {
    run.fn = 1.0 + fn_rate * sim.dynamics().time();
    set_contact_load(sim, run.fn, kFt);
    sim.step();
    const Pair& pr = sim.dynamics().neighbours().pairs().at(0);
    EXPECT_TRUE(pr.history.touching) << "step " << k;
    run.ratio = coulomb_ratio(sim, c);  // asserts kt |xi| <= mu kn overlap (1 + 1e-9)
    if (run.ratio >= 1.0 - 1e-9) ++run.at_limit;
    run.xi = pr.history.contact.xi;
    const PairGeometry& g = sim.dynamics().force_balance().terms().at(0).g;
    const auto& u = sim.integrator().velocities().u;
    Vec6 u6;
    u6 << u[0], u[1];
    run.slip = FrictionalContact::slip_rate(g, u6);
    run.overlap = g.overlap();
    run.expected_slip = (kFt - c.mu * c.kn * g.overlap()) * slip_mobility(g);
  }
  run.rebuilt = sim.dynamics().neighbours().rebuilds() != rebuilds;
  return run;
}

TEST(TwoBodyContact, CoulombLimitHoldsAndIsReachedWhenSliding) {
  for (IntegratorType type : {IntegratorType::Implicit, IntegratorType::Heun}) {
    for (double fn_rate : {0.0, 0.02, -0.02}) {
      SCOPED_TRACE(std::string(to_string(type)) + " fn_rate=" + std::to_string(fn_rate));
      const SlidingRun r = run_sliding(type, fn_rate);
      EXPECT_FALSE(r.rebuilt);  // the terms read after each step are the step's own
      // Sliding: the spring sits at the Coulomb cap, from early on (the stretch builds up at
      // the free slip rate ~ 0.08 to the cap 1e-3 within ~ 20 steps) to the end.
      EXPECT_NEAR(r.ratio, 1.0, 1e-9);
      EXPECT_GT(r.at_limit, r.steps * 9 / 10);
      EXPECT_GT(r.xi, 0.0);  // stretched in the direction of the load (kt xi -> +ft)
      // ... and it keeps slipping: the excess ft - mu fn ~ 0.3 drives a slip rate of order
      // 0.3 / (dashpot + drag resistance ~ 10) ~ 0.03; a stuck contact has |slip| < 1e-9.
      EXPECT_GT(r.slip, 1e-2);
      // The normal balance kn overlap = fn holds to the (first-order) lag of the normal mode
      // behind the ramp, (fn_rate / 4.2) / fn < 5e-3, and the O(dt) discretisation drift of
      // the rotating pair (~1e-4).
      EXPECT_NEAR(r.overlap * 1e3 / r.fn, 1.0, 1e-2);
    }
  }
}

// Sliding speed against the analytic one. Heun averages the velocities of two geometries a
// rotation of ~ 3e-5 rad apart and reads the slip at the second; the overlap lags the ramp. Both
// effects are O(dt) = 1e-3 relative at most, hence the tolerance.
TEST(TwoBodyContact, SlidingSpeedMatchesAnalyticHeun) {
  for (double fn_rate : {0.0, 0.02, -0.02}) {
    SCOPED_TRACE("fn_rate=" + std::to_string(fn_rate));
    const SlidingRun r = run_sliding(IntegratorType::Heun, fn_rate);
    EXPECT_NEAR(r.slip / r.expected_slip, 1.0, 1e-3) << r.slip << " vs " << r.expected_slip;
  }
}

// Same for the implicit integrator (the start-of-step geometry is the one read, so it should be
// even closer). A sliding contact must get no tangential stiffness in the matrix
// (docs/model.md s. 7).
TEST(TwoBodyContact, SlidingSpeedMatchesAnalyticImplicit) {
  for (double fn_rate : {0.0, 0.02, -0.02}) {
    SCOPED_TRACE("fn_rate=" + std::to_string(fn_rate));
    const SlidingRun r = run_sliding(IntegratorType::Implicit, fn_rate);
    EXPECT_NEAR(r.slip / r.expected_slip, 1.0, 1e-3) << r.slip << " vs " << r.expected_slip;
  }
}

// ft < mu fn: the contact sticks and the spring carries the load, kt xi = ft. The slip mode
// relaxes at ~ kt / (dashpot + drag) ~ 500 / 12 ~ 40 per unit time and the normal mode at
// kn / 240 ~ 4.2, so after t = 5 the transient is ~ e^-20 ~ 2e-9 of the load; 1e-6 is safe.
TEST(TwoBodyContact, StickingSpringCarriesTangentialLoad) {
  constexpr double kFn = 1.0, kFt = 0.3;  // ft < mu fn = 0.5
  for (IntegratorType type : {IntegratorType::Implicit, IntegratorType::Heun}) {
    SCOPED_TRACE(to_string(type));
    const Config cfg = two_body_config(type, 1e-3, 1e3);
    const ContactParams c = params_of(cfg);
    Simulation sim(cfg, two_body_scene(0.5, 0.5, -2.0 * kFn / c.kn));
    double ratio = 0.0;
    for (int k = 0; k < 5000; ++k) {
      set_contact_load(sim, kFn, kFt);
      sim.step();
      ASSERT_TRUE(sim.dynamics().neighbours().pairs().at(0).history.touching) << "step " << k;
      ratio = coulomb_ratio(sim, c);
    }
    const Pair& pr = sim.dynamics().neighbours().pairs().at(0);
    EXPECT_NEAR(c.kt * pr.history.contact.xi / kFt, 1.0, 1e-6) << "xi " << pr.history.contact.xi;
    EXPECT_NEAR(geometry(sim).overlap() * c.kn / kFn, 1.0, 1e-6);
    // Stuck, below the cap: kt xi / (mu kn overlap) = ft / (mu fn) = 0.6.
    EXPECT_NEAR(ratio, kFt / (c.mu * kFn), 1e-6);
    for (const Vec3& u : sim.integrator().velocities().u) EXPECT_LT(u.norm(), 1e-8);
  }
}

// ---------------------------------------------------------------------------------------------
// 4. Tangential spring reset (docs/model.md section 5: a contact starts with xi = 0 and ends as
// soon as h > 0). Build up xi with a sticking load, pull the discs apart, then push them back.
TEST(TwoBodyContact, TangentialSpringResetsWhenContactOpens) {
  for (IntegratorType type : {IntegratorType::Implicit, IntegratorType::Heun}) {
    SCOPED_TRACE(to_string(type));
    const Config cfg = two_body_config(type, 1e-3, 1e3);
    const ContactParams c = params_of(cfg);
    Simulation sim(cfg, two_body_scene(0.5, 0.5, -2.0 / c.kn));
    const std::size_t rebuilds = sim.dynamics().neighbours().rebuilds();
    const auto& pairs = sim.dynamics().neighbours().pairs();

    // Phase 1: stick with kt xi = 0.3.
    for (int k = 0; k < 2000; ++k) {
      set_contact_load(sim, 1.0, 0.3);
      sim.step();
    }
    ASSERT_TRUE(pairs.at(0).history.touching);
    ASSERT_NEAR(c.kt * pairs.at(0).history.contact.xi, 0.3, 1e-3);

    // Phase 2: reverse the normal load (no tangential load). Every step that starts with h > 0
    // must leave the contact inactive with xi exactly 0; while still overlapping, xi survives.
    int open_steps = 0, closed_steps = 0, stretched_steps = 0;
    for (int k = 0; k < 20000 && geometry(sim).h < 0.005; ++k) {
      const double h_start = geometry(sim).h;
      set_contact_load(sim, -1.0, 0.0);
      sim.step();
      const Pair& pr = pairs.at(0);
      if (h_start > 0.0) {
        ++open_steps;
        EXPECT_FALSE(pr.history.touching) << "h " << h_start;
        EXPECT_EQ(pr.history.contact.xi, 0.0) << "h " << h_start;
      } else {
        ++closed_steps;
        EXPECT_TRUE(pr.history.touching) << "h " << h_start;
        // The stretch is kept (relaxing, and capped by Coulomb with the end-of-step overlap)
        // while the contact lasts.
        coulomb_ratio(sim, c);
        if (geometry(sim).overlap() > 0.0 && pr.history.contact.xi != 0.0) ++stretched_steps;
      }
    }
    EXPECT_GT(closed_steps, 0);
    EXPECT_GT(stretched_steps, 0);
    EXPECT_GT(open_steps, 10);
    ASSERT_GE(geometry(sim).h, 0.005);

    // Phase 3: push back with the tangential load on. On the first step in contact the stretch
    // starts from 0: xi = cap(v_s dt) with v_s the slip rate of the step's velocities at the
    // start-of-step geometry (PairTerm::g for the implicit integrator; for Heun the terms hold
    // the predicted geometry, an O(dt) difference) and the cap at the end-of-step overlap --
    // the old stretch must not come back.
    bool recontact = false;
    for (int k = 0; k < 20000 && !recontact; ++k) {
      set_contact_load(sim, 1.0, 0.3);
      sim.step();
      const Pair& pr = pairs.at(0);
      if (!pr.history.touching) {
        EXPECT_EQ(pr.history.contact.xi, 0.0);
        continue;
      }
      recontact = true;
      const PairTerm& term = sim.dynamics().force_balance().terms().at(0);
      const auto& u = sim.integrator().velocities().u;
      Vec6 u6;
      u6 << u[0], u[1];
      const double vs = FrictionalContact::slip_rate(term.g, u6);
      const double cap = c.mu * c.kn * std::max(geometry(sim).overlap(), 0.0) / c.kt;
      const double expected = std::clamp(vs * cfg.integrator.dt, -cap, cap);
      const double tol = type == IntegratorType::Implicit ? 1e-9 : 1e-2;
      EXPECT_NEAR(pr.history.contact.xi, expected, 1e-15 + tol * std::abs(expected));
      // The old stretch (6e-4) is far above anything one step can build.
      EXPECT_LT(std::abs(pr.history.contact.xi), 1e-5);
    }
    EXPECT_TRUE(recontact);
    EXPECT_EQ(sim.dynamics().neighbours().rebuilds(), rebuilds);
  }
}

// ---------------------------------------------------------------------------------------------
// 5. Sliding contacts at large implicit steps (docs/low_j.md).
//
// A contact left sliding at the Coulomb cap whose tangential load is then removed must come to
// rest: the stretched spring drives the slip back, the contact sticks (|xi| < cap) and relaxes to
// xi = 0, U = 0. The implicit integrator carries a sliding contact's force explicitly (no
// tangential stiffness, docs/model.md s. 7). At a step where that explicit cap force reverses the
// slip by more than the cap within one step (kn = 1e4, dt = 0.02: cap xi = overlap = 1e-4, slip per
// step ~ 0.5 x slip mobility (~0.1) x dt ~ 1e-3), treating the contact as still sliding flips xi
// from +cap to -cap every step: a chatter that never sticks, whose friction force averages to
// zero and spins the discs back and forth. A contact whose slip opposes its spring is not
// sliding; it must get its tangential stiffness in that same step.
TEST(TwoBodyContact, SlidingContactReleasedAtLargeImplicitStepSticksAndRelaxes) {
  constexpr double kFn = 1.0, kDt = 0.02;
  Config cfg = two_body_config(IntegratorType::Implicit, kDt, 1e4);
  const ContactParams c = params_of(cfg);
  Simulation sim(cfg, two_body_scene(0.5, 0.5, -2.0 * kFn / c.kn));
  const std::size_t rebuilds = sim.dynamics().neighbours().rebuilds();
  const auto& pairs = sim.dynamics().neighbours().pairs();
  // Phase 1: slide (ft = 0.8 > mu fn): the spring sits at +cap.
  for (int k = 0; k < 200; ++k) {
    set_contact_load(sim, kFn, 0.8);
    sim.step();
  }
  ASSERT_TRUE(pairs.at(0).history.touching);
  ASSERT_NEAR(coulomb_ratio(sim, c), 1.0, 1e-9);
  ASSERT_GT(pairs.at(0).history.contact.xi, 0.0);
  // Phase 2: tangential load off. The slip mode relaxes at ~ kt / (dashpot + drag) ~ 400 per
  // unit time, i.e. by 1/(1 + 8) per implicit step: after 100 steps nothing is left.
  int sign_flips = 0;
  double last_xi = pairs.at(0).history.contact.xi;
  for (int k = 0; k < 100; ++k) {
    set_contact_load(sim, kFn, 0.0);
    sim.step();
    const double xi = pairs.at(0).history.contact.xi;
    // Round-off (|xi| ~ 1e-21 once relaxed) may change sign; a chatter flips at the cap 1e-4.
    if (xi * last_xi < 0.0 && std::abs(xi) > 1e-12) ++sign_flips;
    last_xi = xi;
  }
  const Pair& pr = pairs.at(0);
  ASSERT_TRUE(pr.history.touching);
  EXPECT_EQ(sign_flips, 0) << "the spring chatters between the Coulomb caps";
  EXPECT_FALSE(pr.history.contact.sliding);
  EXPECT_LT(c.kt * std::abs(pr.history.contact.xi), 1e-8) << "xi " << pr.history.contact.xi;
  for (const Vec3& u : sim.integrator().velocities().u) EXPECT_LT(u.norm(), 1e-8);
  EXPECT_EQ(sim.dynamics().neighbours().rebuilds(), rebuilds);
}

// The same large step must not make a genuinely sliding contact stick: under ft = 0.8 > mu fn
// the spring stays at the cap and the slip rate is the analytic one.
TEST(TwoBodyContact, SlidingSpeedMatchesAnalyticImplicitLargeStep) {
  constexpr double kFn = 1.0, kFt = 0.8, kDt = 0.02;
  Config cfg = two_body_config(IntegratorType::Implicit, kDt, 1e4);
  const ContactParams c = params_of(cfg);
  Simulation sim(cfg, two_body_scene(0.5, 0.5, -2.0 * kFn / c.kn));
  for (int k = 0; k < 300; ++k) {
    set_contact_load(sim, kFn, kFt);
    sim.step();
  }
  const Pair& pr = sim.dynamics().neighbours().pairs().at(0);
  ASSERT_TRUE(pr.history.touching);
  EXPECT_TRUE(pr.history.contact.sliding);
  EXPECT_NEAR(coulomb_ratio(sim, c), 1.0, 1e-9);
  const PairGeometry& g = sim.dynamics().force_balance().terms().at(0).g;
  const auto& u = sim.integrator().velocities().u;
  Vec6 u6;
  u6 << u[0], u[1];
  const double slip = FrictionalContact::slip_rate(g, u6);
  const double expected = (kFt - c.mu * c.kn * g.overlap()) * slip_mobility(g);
  EXPECT_NEAR(slip / expected, 1.0, 1e-3) << slip << " vs " << expected;
}

}  // namespace
}  // namespace sheardiff

namespace sheardiff {
namespace {

// contact.stiffness = "mean_radius" (LF_DEM's convention): the spring force and stiffness of a
// pair scale with (a_i + a_j) / d, 1.2 for small-large and 1.4 for large-large pairs, while the
// Coulomb cap (a ratio of the two stiffnesses) does not move.
TEST(FrictionalContact, MeanRadiusStiffnessScalesEachPair) {
  const FrictionalContact uniform{1e4, 5e3, 0.5, false}, scaled{1e4, 5e3, 0.5, true};
  for (const auto& [ai, aj, factor] :
       {std::tuple{0.5, 0.5, 1.0}, {0.5, 0.7, 1.2}, {0.7, 0.7, 1.4}}) {
    const PairGeometry g = PairGeometry::make(Vec2(ai + aj - 0.003, 0.0), ai, aj);
    const Vec6 fu = uniform.spring_force(g, 1e-4), fs = scaled.spring_force(g, 1e-4);
    EXPECT_NEAR((fs - factor * fu).norm(), 0.0, 1e-12 * fu.norm());
    EXPECT_NEAR((scaled.stiffness(g, false) - factor * uniform.stiffness(g, false)).norm(), 0.0,
                1e-9);
    double xu = 1.0, xs = 1.0;
    EXPECT_EQ(uniform.apply_coulomb(g, xu), scaled.apply_coulomb(g, xs));
    EXPECT_DOUBLE_EQ(xu, xs);
  }
}

}  // namespace
}  // namespace sheardiff
