// Pair laws of docs/model.md sections 4 and 5: the lubrication coefficients and their 6x6 block,
// and the frictional spring contact.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "sheardiff/interactions/contact.hpp"
#include "sheardiff/interactions/lubrication.hpp"
#include "sheardiff/interactions/pair_geometry.hpp"
#include "sheardiff/solver/force_balance.hpp"

namespace sheardiff {
namespace {

// The two size pairs of the bidisperse mixture (diameters 1-1 and 1-1.4).
struct Radii {
  double ai, aj;
};
const Radii kSizePairs[] = {{0.5, 0.5}, {0.5, 0.7}, {0.7, 0.5}};

// docs/model.md section 4, written out independently of the library (eta = 1).
PairResistance reference_coefficients(double ai, double aj, double h, double delta) {
  const double he = std::max(h, 0.0) + delta;
  const double ln = 1.0 / he;
  const double lt = ln > 1.0 ? std::log(ln) : 0.0;
  const double s = ai + aj;
  const double c = 6.0 * kPi;
  PairResistance r;
  r.xa = c * 2.0 * ai * ai * aj * aj / (s * s * s) * ln;
  r.ya = c * 4.0 / 15.0 * ai * aj * (2 * ai * ai + ai * aj + 2 * aj * aj) / (s * s * s) * lt;
  r.beta_i = c * 2.0 / 15.0 * ai * ai * aj * (4 * ai + aj) / (s * s) * lt;
  r.beta_j = c * 2.0 / 15.0 * ai * aj * aj * (ai + 4 * aj) / (s * s) * lt;
  r.gam_ii = c * 8.0 / 15.0 * ai * ai * ai * aj / s * lt;
  r.gam_jj = c * 8.0 / 15.0 * ai * aj * aj * aj / s * lt;
  r.gam_ij = c * 2.0 / 15.0 * ai * ai * aj * aj / s * lt;
  return r;
}

std::vector<double> as_vector(const PairResistance& r) {
  return {r.xa, r.ya, r.beta_i, r.beta_j, r.gam_ii, r.gam_jj, r.gam_ij};
}

// Both sides evaluate the same closed form with a different operation order, so they agree to
// a few ulp; 1e-13 relative leaves ample room and still catches any wrong factor.
void expect_coefficients_near(const PairResistance& got, const PairResistance& want, double rel) {
  const auto g = as_vector(got), w = as_vector(want);
  const char* names[] = {"xa", "ya", "beta_i", "beta_j", "gam_ii", "gam_jj", "gam_ij"};
  for (std::size_t k = 0; k < g.size(); ++k)
    EXPECT_NEAR(g[k], w[k], rel * std::abs(w[k])) << names[k];
}

Vec2 unit(double angle) {
  return {std::cos(angle), std::sin(angle)};
}

TEST(Lubrication, CoefficientsMatchClosedFormsForBothSizePairs) {
  const Lubrication lub{0.01, 0.5};
  const double gaps[] = {1e-6, 1e-3, 0.01, 0.05, 0.1, 0.25, 0.49, 0.8};
  for (const Radii& r : kSizePairs)
    for (double h : gaps) {
      SCOPED_TRACE(testing::Message() << "ai=" << r.ai << " aj=" << r.aj << " h=" << h);
      expect_coefficients_near(lub.coefficients(r.ai, r.aj, h),
                               reference_coefficients(r.ai, r.aj, h, 0.01), 1e-13);
    }
}

TEST(Lubrication, EqualSpheresReproduceTheQuotedNumbers) {
  // docs/model.md: XA = 2.356/(h+delta), YA = 1.571 Lt, beta = 0.785 Lt, gam_ii = 0.628 Lt,
  // gam_ij = 0.157 Lt, printed to 4 significant digits, so they hold to half a unit of the last
  // printed digit (5e-4). The exact values are 3pi/4, pi/2, pi/4, pi/5 and pi/20.
  const double delta = 0.01;
  const Lubrication lub{delta, 0.5};
  for (double h : {0.0, 0.003, 0.02, 0.1, 0.3}) {
    SCOPED_TRACE(testing::Message() << "h=" << h);
    const PairResistance c = lub.coefficients(0.5, 0.5, h);
    const double he = h + delta, lt = std::log(1.0 / he);
    EXPECT_NEAR(c.xa * he, 2.356, 5e-4);
    EXPECT_NEAR(c.ya / lt, 1.571, 5e-4);
    EXPECT_NEAR(c.beta_i / lt, 0.785, 5e-4);
    EXPECT_NEAR(c.beta_j / lt, 0.785, 5e-4);
    EXPECT_NEAR(c.gam_ii / lt, 0.628, 5e-4);
    EXPECT_NEAR(c.gam_jj / lt, 0.628, 5e-4);
    EXPECT_NEAR(c.gam_ij / lt, 0.157, 5e-4);
    // And the exact rational multiples of pi, to round-off.
    EXPECT_NEAR(c.xa * he, 0.75 * kPi, 1e-13);
    EXPECT_NEAR(c.ya / lt, 0.5 * kPi, 1e-13);
    EXPECT_NEAR(c.beta_i / lt, 0.25 * kPi, 1e-13);
    EXPECT_NEAR(c.gam_ii / lt, 0.2 * kPi, 1e-13);
    EXPECT_NEAR(c.gam_ij / lt, 0.05 * kPi, 1e-13);
  }
}

TEST(Lubrication, UnequalPairHandComputedValues) {
  // a_i = 0.5, a_j = 0.7, s = 1.2, h = 0.09 so h + delta = 0.1: Ln = 10, Lt = ln 10.
  // XA = 6 pi * 2 * 0.25 * 0.49 / 1.728 * 10; beta_i = 6 pi (2/15) 0.25*0.7*2.7/1.44 Lt;
  // beta_j = 6 pi (2/15) 0.5*0.49*3.3/1.44 Lt.
  const Lubrication lub{0.01, 0.5};
  const PairResistance c = lub.coefficients(0.5, 0.7, 0.09);
  const double lt = std::log(10.0), six_pi = 6.0 * kPi;
  EXPECT_NEAR(c.xa, six_pi * 0.245 / 1.728 * 10.0, 1e-12);
  EXPECT_NEAR(c.ya, six_pi * (4.0 / 15.0) * 0.35 * (0.5 + 0.35 + 0.98) / 1.728 * lt, 1e-12);
  EXPECT_NEAR(c.beta_i, six_pi * (2.0 / 15.0) * 0.4725 / 1.44 * lt, 1e-12);
  EXPECT_NEAR(c.beta_j, six_pi * (2.0 / 15.0) * 0.8085 / 1.44 * lt, 1e-12);
  EXPECT_NEAR(c.gam_ii, six_pi * (8.0 / 15.0) * 0.0875 / 1.2 * lt, 1e-12);
  EXPECT_NEAR(c.gam_jj, six_pi * (8.0 / 15.0) * 0.1715 / 1.2 * lt, 1e-12);
  EXPECT_NEAR(c.gam_ij, six_pi * (2.0 / 15.0) * 0.1225 / 1.2 * lt, 1e-12);
  // Swapping i and j swaps the i/j coefficients and leaves the symmetric ones.
  const PairResistance d = lub.coefficients(0.7, 0.5, 0.09);
  EXPECT_DOUBLE_EQ(d.xa, c.xa);
  EXPECT_DOUBLE_EQ(d.ya, c.ya);
  EXPECT_DOUBLE_EQ(d.beta_i, c.beta_j);
  EXPECT_DOUBLE_EQ(d.gam_ii, c.gam_jj);
  EXPECT_DOUBLE_EQ(d.gam_ij, c.gam_ij);
}

TEST(Lubrication, LogarithmicModesAreCutWhereOneOverGapIsAtMostOne) {
  // Lt = ln(1/(h+delta)) only while 1/(h+delta) > 1, i.e. h < 1 - delta = 0.99; beyond it every
  // log mode is exactly zero while the squeeze term 1/(h+delta) stays.
  const Lubrication lub{0.01, 0.5};
  for (const Radii& r : kSizePairs) {
    for (double h : {0.995, 1.0, 1.5, 3.0}) {
      SCOPED_TRACE(testing::Message() << "ai=" << r.ai << " aj=" << r.aj << " h=" << h);
      const PairResistance c = lub.coefficients(r.ai, r.aj, h);
      EXPECT_EQ(c.ya, 0.0);
      EXPECT_EQ(c.beta_i, 0.0);
      EXPECT_EQ(c.beta_j, 0.0);
      EXPECT_EQ(c.gam_ii, 0.0);
      EXPECT_EQ(c.gam_jj, 0.0);
      EXPECT_EQ(c.gam_ij, 0.0);
      const double s = r.ai + r.aj;
      EXPECT_NEAR(c.xa, 6 * kPi * 2 * r.ai * r.ai * r.aj * r.aj / (s * s * s) / (h + 0.01),
                  1e-13 * c.xa);
    }
    // Just below the cut Lt is small and positive: ln(1/0.99).
    const PairResistance c = lub.coefficients(r.ai, r.aj, 0.98);
    EXPECT_GT(c.ya, 0.0);
    expect_coefficients_near(c, reference_coefficients(r.ai, r.aj, 0.98, 0.01), 1e-12);
  }
  // A larger delta moves the cut: delta = 0.3 cuts from h = 0.7 on.
  const Lubrication wide{0.3, 0.5};
  EXPECT_EQ(wide.coefficients(0.5, 0.5, 0.71).ya, 0.0);
  EXPECT_GT(wide.coefficients(0.5, 0.5, 0.69).ya, 0.0);
}

TEST(Lubrication, ActsOnlyBelowTheCutOff) {
  const Lubrication lub{0.01, 0.5};
  EXPECT_TRUE(lub.acts(0.0));
  EXPECT_TRUE(lub.acts(0.49));
  EXPECT_FALSE(lub.acts(0.5));
  EXPECT_FALSE(lub.acts(0.7));
}

TEST(Lubrication, ContinuousAtContact) {
  // Just open (h = 1e-12), touching (h = 0) and in contact (h = -0.01, dashpots frozen at
  // h = 0) give the same resistance: the relative change is ~ 1e-12 / delta = 1e-10 < 1e-9.
  const Lubrication lub{0.01, 0.5};
  for (const Radii& r : kSizePairs) {
    const PairResistance at0 = lub.coefficients(r.ai, r.aj, 0.0);
    expect_coefficients_near(lub.coefficients(r.ai, r.aj, 1e-12), at0, 1e-9);
    expect_coefficients_near(lub.coefficients(r.ai, r.aj, -0.01), at0, 1e-9);
    expect_coefficients_near(lub.coefficients(r.ai, r.aj, -0.3), at0, 1e-15);
    // At h = 0 itself: Ln = 1/delta, Lt = ln(1/delta).
    expect_coefficients_near(at0, reference_coefficients(r.ai, r.aj, 0.0, 0.01), 1e-13);
  }
}

// ---- The 6x6 block R_pair ------------------------------------------------------------------

double max_abs(const Mat6& m) {
  return m.cwiseAbs().maxCoeff();
}

TEST(PairResistanceMatrix, SymmetricAndPositiveSemiDefinite) {
  const Lubrication lub{0.01, 0.5};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * kPi);
  for (const Radii& r : kSizePairs)
    for (double h : {-0.01, 0.0, 1e-4, 0.02, 0.3, 0.49, 1.2}) {
      for (int rep = 0; rep < 8; ++rep) {
        const Vec2 n = unit(angle(rng));
        const Mat6 m = lub.coefficients(r.ai, r.aj, h).matrix(n, perp(n));
        SCOPED_TRACE(testing::Message() << "ai=" << r.ai << " aj=" << r.aj << " h=" << h);
        // Built from the same products on both sides of the diagonal: symmetric to round-off.
        EXPECT_LE(max_abs(m - m.transpose()), 1e-14 * max_abs(m));
        Eigen::SelfAdjointEigenSolver<Mat6> es(m);
        const auto ev = es.eigenvalues();
        EXPECT_GE(ev.minCoeff(), -1e-12 * ev.maxCoeff());
        // Translation is always a null vector, so at least two eigenvalues vanish.
        EXPECT_LE(std::abs(ev[0]), 1e-12 * ev.maxCoeff());
        EXPECT_LE(std::abs(ev[1]), 1e-12 * ev.maxCoeff());
      }
    }
}

TEST(PairResistanceMatrix, ForceAndTorqueFollowTheModelFormulas) {
  // -R U must be the force/torque of docs/model.md section 4 written component by component.
  const Lubrication lub{0.01, 0.5};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uni(-1.0, 1.0), angle(0.0, 2.0 * kPi);
  for (const Radii& r : kSizePairs)
    for (double h : {0.0, 0.04, 0.3}) {
      const PairResistance c = lub.coefficients(r.ai, r.aj, h);
      for (int rep = 0; rep < 5; ++rep) {
        const Vec2 n = unit(angle(rng)), t = perp(n);
        Vec6 u;
        for (int k = 0; k < 6; ++k) u[k] = uni(rng);
        const Vec6 f = -c.matrix(n, t) * u;
        const Vec2 ui = u.head<2>(), uj = u.segment<2>(3);
        const double wi = u[2], wj = u[5];
        const Vec2 du = ui - uj;
        const Vec2 fi =
            -c.xa * n.dot(du) * n - c.ya * t.dot(du) * t - (c.beta_i * wi + c.beta_j * wj) * t;
        const double ti = -c.beta_i * t.dot(du) - c.gam_ii * wi - c.gam_ij * wj;
        const double tj = -c.beta_j * t.dot(du) - c.gam_ij * wi - c.gam_jj * wj;
        const double scale = c.matrix(n, t).cwiseAbs().maxCoeff() * u.cwiseAbs().maxCoeff();
        EXPECT_NEAR(f[0], fi.x(), 1e-13 * scale);
        EXPECT_NEAR(f[1], fi.y(), 1e-13 * scale);
        EXPECT_NEAR(f[2], ti, 1e-13 * scale);
        EXPECT_NEAR(f[3], -fi.x(), 1e-13 * scale);
        EXPECT_NEAR(f[4], -fi.y(), 1e-13 * scale);
        EXPECT_NEAR(f[5], tj, 1e-13 * scale);
      }
    }
}

TEST(PairResistanceMatrix, RigidMotionsAreInTheNullSpaceAtContact) {
  // At r = s: translations in x and y and the rigid rotation of the pair (about i, about the
  // midpoint, about the contact point) produce no lubrication force: |R U| <= 1e-12 |R| |U|.
  const Lubrication lub{0.01, 0.5};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * kPi), uni(-2.0, 2.0);
  for (const Radii& r : kSizePairs) {
    const double s = r.ai + r.aj;
    const Mat6 ref_block = lub.coefficients(r.ai, r.aj, 0.0).matrix(Vec2::UnitX(), Vec2::UnitY());
    for (int rep = 0; rep < 10; ++rep) {
      const Vec2 n = unit(angle(rng)), t = perp(n);
      const Mat6 m = lub.coefficients(r.ai, r.aj, 0.0).matrix(n, t);
      const double rn = m.norm();
      EXPECT_NEAR(rn, ref_block.norm(), 1e-12 * rn);  // rotation invariant
      const Vec2 xi = Vec2(uni(rng), uni(rng));
      const Vec2 xj = xi + s * n;
      const double omega = uni(rng);
      const auto rigid_rotation = [&](const Vec2& centre) {
        Vec6 u;
        const Vec2 vi = omega * perp(xi - centre), vj = omega * perp(xj - centre);
        u << vi, omega, vj, omega;
        return u;
      };
      std::vector<std::pair<const char*, Vec6>> modes;
      Vec6 tx, ty;
      tx << 1, 0, 0, 1, 0, 0;
      ty << 0, 1, 0, 0, 1, 0;
      modes.emplace_back("translation x", tx);
      modes.emplace_back("translation y", ty);
      modes.emplace_back("rotation about i", rigid_rotation(xi));
      modes.emplace_back("rotation about midpoint", rigid_rotation(0.5 * (xi + xj)));
      modes.emplace_back("rotation about contact", rigid_rotation(xi + r.ai * n));
      modes.emplace_back("rotation about origin", rigid_rotation(Vec2::Zero()));
      for (const auto& [name, u] : modes) {
        SCOPED_TRACE(testing::Message() << name << " ai=" << r.ai << " aj=" << r.aj);
        EXPECT_LE((m * u).norm(), 1e-12 * rn * u.norm());
      }
      // A relative motion is not free: squeezing costs 2 XA along n on each particle.
      Vec6 squeeze;
      squeeze << n, 0.0, -n, 0.0;
      const double xa = lub.coefficients(r.ai, r.aj, 0.0).xa;
      EXPECT_NEAR((m * squeeze - 2.0 * xa * squeeze).norm(), 0.0, 1e-12 * rn);
    }
  }
}

TEST(PairResistanceMatrix, RotationIsNotFreeAwayFromContact) {
  // The rigid rotation is a null vector only at r = s: at r = 1.1 s the shear coefficient
  // times the lever arm no longer balances the rotation couplings, so the null-space test
  // above is not vacuous. F_i.t = (YA r - beta_i - beta_j) Omega with u_i = 0, u_j = Omega r t.
  const Lubrication lub{0.01, 0.5};
  const double ai = 0.5, aj = 0.7, s = ai + aj, r = 1.1 * s, h = 2.0 * r / s - 2.0;
  const PairResistance c = lub.coefficients(ai, aj, h);
  const Vec2 n = Vec2::UnitX(), t = perp(n);
  Vec6 u;
  u << 0.0, 0.0, 1.0, r * t, 1.0;
  const Vec6 f = -c.matrix(n, t) * u;
  const double expected = (c.ya * r - c.beta_i - c.beta_j);
  EXPECT_NEAR(f.segment<2>(0).dot(t), expected, 1e-12 * c.ya);
  EXPECT_GT(std::abs(expected), 1e-3 * c.ya);
}

TEST(PairResistanceMatrix, ForceBalanceUsesTheContactDashpotAtZeroGap) {
  // In contact the pair block is R_pair at h = 0 (plus dt K for implicit springs only).
  Particles p;
  p.resize(2);
  p.n_mobile = 2;
  p.radius = {0.5, 0.7};
  p.position = {Vec2(3.0, 3.0), Vec2(3.0, 3.0) + 1.19 * unit(0.4)};  // overlap 0.01
  p.unwrapped = p.position;
  Box box;
  box.lx = box.ly = 10.0;
  box.lees_edwards = true;
  std::vector<Pair> pairs(1);
  pairs[0].i = 0;
  pairs[0].j = 1;
  ForceBalance::update_contacts(p, box, pairs);
  ASSERT_TRUE(pairs[0].history.touching);
  const Lubrication lub{0.01, 0.5};
  const FrictionalContact contact{1e4, 5e3, 0.5};
  ForceBalance fb(lub, contact, 3, true);
  fb.on_rebuild(p, pairs);
  Velocities v;
  ASSERT_TRUE(fb.solve(p, box, ImposedFlow{0.0, 0.0}, pairs, 0.0, nullptr, v));
  const PairTerm& term = fb.terms()[0];
  ASSERT_TRUE(term.on);
  const Mat6 want = lub.coefficients(0.5, 0.7, 0.0).matrix(term.g.n, term.g.t);
  EXPECT_LE(max_abs(term.m - want), 1e-13 * max_abs(want));
  // Implicit springs add exactly dt K.
  const double dt = 0.02;
  ASSERT_TRUE(fb.solve(p, box, ImposedFlow{0.0, 0.0}, pairs, dt, nullptr, v));
  const Mat6 want_k = want + dt * contact.stiffness(term.g, false);
  EXPECT_LE(max_abs(fb.terms()[0].m - want_k), 1e-13 * max_abs(want_k));
}

// ---- Frictional contact ----------------------------------------------------------------------

PairGeometry touching(double ai, double aj, double overlap, double angle) {
  return PairGeometry::make((ai + aj - overlap) * unit(angle), ai, aj);
}

TEST(FrictionalContact, GeometryOfAnOverlappingPair) {
  const PairGeometry g = touching(0.5, 0.7, 0.02, 0.9);
  EXPECT_NEAR(g.overlap(), 0.02, 1e-14);
  EXPECT_NEAR(g.h, 2.0 * 1.18 / 1.2 - 2.0, 1e-14);
  EXPECT_LT(g.h, 0.0);
  EXPECT_NEAR(g.n.norm(), 1.0, 1e-15);
  EXPECT_NEAR(g.n.dot(g.t), 0.0, 1e-15);
  EXPECT_NEAR(cross(g.n, g.t), 1.0, 1e-15);  // t = z x n
}

TEST(FrictionalContact, NormalSpringForce) {
  const FrictionalContact c{1e4, 5e3, 0.5};
  for (const Radii& r : kSizePairs)
    for (double overlap : {1e-5, 3e-3, 0.05}) {
      const PairGeometry g = touching(r.ai, r.aj, overlap, 2.2);
      const Vec6 f = c.spring_force(g, 0.0);
      const Vec2 fi_expected = -c.kn * overlap * g.n;  // pushes i away from j
      const double tol = 1e-9 * c.kn * overlap;        // overlap recomputed from r: ~1e-16 abs
      EXPECT_NEAR(f[0], fi_expected.x(), tol);
      EXPECT_NEAR(f[1], fi_expected.y(), tol);
      EXPECT_NEAR(f[3], -fi_expected.x(), tol);
      EXPECT_NEAR(f[4], -fi_expected.y(), tol);
      EXPECT_EQ(f[2], 0.0);
      EXPECT_EQ(f[5], 0.0);
    }
}

TEST(FrictionalContact, TangentialSpringForceAndTorques) {
  // F_i = +kt xi t, F_j = -F_i, T_i = a_i kt xi, T_j = a_j kt xi (docs/model.md section 5).
  const FrictionalContact c{1e4, 5e3, 0.5};
  const PairGeometry g = touching(0.5, 0.7, 0.0, 0.7);  // exactly touching: no normal force
  const double xi = -3e-4;
  const Vec6 f = c.spring_force(g, xi);
  const double ft = c.kt * xi;
  const double tol = 1e-12 * std::abs(ft) + 1e-12;
  EXPECT_NEAR(f[0], ft * g.t.x(), tol);
  EXPECT_NEAR(f[1], ft * g.t.y(), tol);
  EXPECT_NEAR(f[2], 0.5 * ft, tol);
  EXPECT_NEAR(f[3], -ft * g.t.x(), tol);
  EXPECT_NEAR(f[4], -ft * g.t.y(), tol);
  EXPECT_NEAR(f[5], 0.7 * ft, tol);
}

TEST(FrictionalContact, StiffnessIsSymmetricPsdAndRankTwo) {
  const FrictionalContact c{1e4, 5e3, 0.5};
  for (const Radii& r : kSizePairs) {
    const PairGeometry g = touching(r.ai, r.aj, 0.01, 1.3);
    const Mat6 k = c.stiffness(g, false);
    const Vec6 m = FrictionalContact::normal_mode(g), w = FrictionalContact::slip_mode(g);
    const Mat6 want = c.kn * m * m.transpose() + c.kt * w * w.transpose();
    EXPECT_LE(max_abs(k - want), 1e-12 * max_abs(want));
    EXPECT_LE(max_abs(k - k.transpose()), 1e-12 * max_abs(k));
    // m = (n, 0, -n, 0) and w = (t, a_i, -t, a_j) are orthogonal, so the non-zero eigenvalues
    // are kn |m|^2 = 2 kn and kt |w|^2 = kt (2 + a_i^2 + a_j^2); the other four vanish.
    EXPECT_NEAR(m.dot(w), 0.0, 1e-15);
    Eigen::SelfAdjointEigenSolver<Mat6> es(k);
    auto ev = es.eigenvalues();
    const double top = ev.maxCoeff();
    for (int q = 0; q < 4; ++q) EXPECT_NEAR(ev[q], 0.0, 1e-12 * top);
    std::vector<double> big = {ev[4], ev[5]};
    std::vector<double> expect = {2.0 * c.kn, c.kt * (2.0 + r.ai * r.ai + r.aj * r.aj)};
    std::sort(expect.begin(), expect.end());
    EXPECT_NEAR(big[0], expect[0], 1e-12 * top);
    EXPECT_NEAR(big[1], expect[1], 1e-12 * top);
    // Sliding: only the normal spring is left.
    const Mat6 ks = c.stiffness(g, true);
    EXPECT_LE(max_abs(ks - c.kn * m * m.transpose()), 1e-12 * c.kn);
    // Frictionless: no tangential stiffness either.
    const FrictionalContact smooth{1e4, 5e3, 0.0};
    EXPECT_LE(max_abs(smooth.stiffness(g, false) - c.kn * m * m.transpose()), 1e-12 * c.kn);
  }
}

TEST(FrictionalContact, StiffnessIsTheLinearisedSpringForce) {
  // K U is the rate of change of the spring force: d/dt (-kn overlap m) = -kn m (m.U) since
  // d(overlap)/dt = m.U, and d/dt (kt xi w) = kt w v_s = -kt w (w.U). So spring(t+dt) ~
  // spring - dt K U. Check against a finite displacement of the pair.
  const FrictionalContact c{1e4, 5e3, 0.5};
  const double ai = 0.5, aj = 0.7;
  const Vec2 xi0(0.0, 0.0), xj0 = (ai + aj - 0.01) * unit(0.3);
  const PairGeometry g = PairGeometry::make(xj0 - xi0, ai, aj);
  Vec6 u;
  u << 0.0, 0.0, 0.0, -0.3 * g.n, 0.0;  // j approaches i along n
  const double dt = 1e-4;
  const PairGeometry g1 = PairGeometry::make(xj0 + dt * u.segment<2>(3) - xi0, ai, aj);
  const Vec6 df = c.spring_force(g1, 0.0) - c.spring_force(g, 0.0);
  const Vec6 lin = -dt * c.stiffness(g, false) * u;
  // Pure normal approach: n does not turn, so the linearisation is exact up to the O(dt^2)
  // change of the overlap (none: straight line) and the round-off of the overlap difference
  // (1e-16 / (0.3 dt) ~ 3e-12 relative).
  EXPECT_LE((df - lin).norm(), 1e-9 * lin.norm());
}

TEST(FrictionalContact, TangentialStiffnessIsTheLinearisedSpringStretch) {
  // Over dt the stretch grows by v_s dt = -(w.U) dt, so the spring force changes by
  // kt w (v_s dt) = -dt kt w w^T U: exactly the tangential part of -dt K U (linear in xi, so
  // the only error is round-off, relative 1e-12 of the force change is ample).
  const FrictionalContact c{1e4, 5e3, 0.5};
  const PairGeometry g = touching(0.5, 0.7, 0.003, -0.8);
  Vec6 u;
  u << 0.01, -0.02, 0.3, -0.04, 0.015, -0.1;
  const double dt = 0.01, xi = 2e-5;
  const Vec6 df =
      c.spring_force(g, xi + FrictionalContact::slip_rate(g, u) * dt) - c.spring_force(g, xi);
  const Vec6 w = FrictionalContact::slip_mode(g);
  const Vec6 lin = -dt * c.kt * w * w.dot(u);
  ASSERT_GT(lin.norm(), 0.0);
  EXPECT_LE((df - lin).norm(), 1e-9 * lin.norm());
  // The normal part of K is blind to the slip and vice versa.
  EXPECT_NEAR((c.stiffness(g, false) - c.stiffness(g, true)).norm(), c.kt * w.squaredNorm(),
              1e-9 * c.kt);
}

TEST(FrictionalContact, SlipRateOfRigidAndRollingMotionsIsZero) {
  // v_s = t.(u_j - u_i) - (a_i omega_i + a_j omega_j).
  for (const Radii& r : kSizePairs) {
    const double s = r.ai + r.aj;
    const PairGeometry g = touching(r.ai, r.aj, 0.0, 0.6);
    // Rolling without slipping (gears): u_i = u_j = 0, a_i w_i + a_j w_j = 0.
    const double w = 0.37;
    Vec6 roll;
    roll << 0.0, 0.0, w, 0.0, 0.0, -w * r.ai / r.aj;
    EXPECT_NEAR(FrictionalContact::slip_rate(g, roll), 0.0, 1e-15);
    // Rigid rotation about the contact point: u_i = -W a_i t, u_j = W a_j t, omega = W.
    const double big_w = -1.3;
    Vec6 rigid;
    rigid << -big_w * r.ai * g.t, big_w, big_w * r.aj * g.t, big_w;
    EXPECT_NEAR(FrictionalContact::slip_rate(g, rigid), 0.0, 1e-14);
    // Rigid rotation about i: u_j = W s t.
    Vec6 about_i;
    about_i << 0.0, 0.0, big_w, big_w * s * g.t, big_w;
    EXPECT_NEAR(FrictionalContact::slip_rate(g, about_i), 0.0, 1e-14);
    // A common translation does not slip.
    Vec6 trans;
    trans << 0.3, -0.8, 0.0, 0.3, -0.8, 0.0;
    EXPECT_NEAR(FrictionalContact::slip_rate(g, trans), 0.0, 1e-15);
    // Signs: j sliding along +t at speed v slips at +v; i spinning at +w slips at -a_i w;
    // j spinning at +w slips at -a_j w (both surfaces at the contact move the same way).
    Vec6 slide;
    slide << 0.0, 0.0, 0.0, 0.25 * g.t, 0.0;
    EXPECT_NEAR(FrictionalContact::slip_rate(g, slide), 0.25, 1e-15);
    Vec6 spin_i = Vec6::Zero(), spin_j = Vec6::Zero();
    spin_i[2] = 2.0;
    spin_j[5] = 2.0;
    EXPECT_NEAR(FrictionalContact::slip_rate(g, spin_i), -2.0 * r.ai, 1e-15);
    EXPECT_NEAR(FrictionalContact::slip_rate(g, spin_j), -2.0 * r.aj, 1e-15);
  }
}

TEST(FrictionalContact, CoulombCapsTheTangentialSpringAndKeepsItsSign) {
  const FrictionalContact c{1e4, 5e3, 0.5};
  const PairGeometry g = touching(0.5, 0.7, 0.004, 0.1);
  const double cap = c.mu * c.kn * g.overlap() / c.kt;  // = 0.5 * 1e4 * 0.004 / 5e3 = 4e-3
  EXPECT_NEAR(cap, 4e-3, 1e-14);  // the overlap is recomputed from r: ~1e-16 absolute
  for (double sign : {1.0, -1.0}) {
    double xi = sign * 3.0 * cap;
    EXPECT_TRUE(c.apply_coulomb(g, xi));
    EXPECT_NEAR(c.kt * std::abs(xi), c.mu * c.kn * g.overlap(), 1e-12 * c.kn * g.overlap());
    EXPECT_EQ(std::signbit(xi), sign < 0);
    EXPECT_TRUE(c.at_coulomb_limit(g, xi));
    // Below the cap: unchanged and sticking.
    double stick = sign * 0.5 * cap;
    EXPECT_FALSE(c.apply_coulomb(g, stick));
    EXPECT_EQ(stick, sign * 0.5 * cap);
    EXPECT_FALSE(c.at_coulomb_limit(g, stick));
  }
  // A contact that has opened (negative overlap) keeps no tangential spring.
  const PairGeometry open = touching(0.5, 0.7, -0.001, 0.1);
  double xi = 1e-5;
  EXPECT_TRUE(c.apply_coulomb(open, xi));
  EXPECT_EQ(xi, 0.0);
  // Frictionless contacts never hold a tangential spring.
  const FrictionalContact smooth{1e4, 5e3, 0.0};
  EXPECT_FALSE(smooth.has_friction());
  double xs = 1e-5;
  EXPECT_FALSE(smooth.apply_coulomb(g, xs));
  EXPECT_EQ(xs, 0.0);
}

}  // namespace
}  // namespace sheardiff
