// The pair laws between two spheres in three dimensions, the first pieces of the 3D engine:
// lubrication (PairResistance::matrix_3d) and the frictional contact's vector spring
// (FrictionalContact::*_3d), each checked against the disc law it must reduce to in the x-y
// plane, against rotation of the pair, against rigid motions at contact, and lubrication against
// Reynolds' squeeze force.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <random>

#include "sheardiff/interactions/contact.hpp"
#include "sheardiff/interactions/lubrication.hpp"
#include "sheardiff/interactions/pair_geometry.hpp"

namespace sheardiff {
namespace {

struct Radii {
  double ai, aj;
};
// The bidisperse mixture's pairs (diameters 1 and 1.4) and a strongly unequal one.
const Radii kSizePairs[] = {{0.5, 0.5}, {0.5, 0.7}, {0.7, 0.5}, {0.5, 2.0}};
const double kGaps[] = {-0.01, 0.0, 1e-3, 0.05, 0.3};

Space3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Space3 v(g(rng), g(rng), g(rng));
  return v.normalized();
}

// Relative difference of two blocks against the larger's size (round-off: ~1e-15).
double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(a.norm(), b.norm());
}

// A pair in the x-y plane: the 3D block on (u_x, u_y, omega_z) of each sphere is the disc block
// of docs/model.md section 4, and the out-of-plane unknowns (u_z, omega_x, omega_y) do not
// couple to them.
TEST(Lubrication3d, InThePlaneItIsTheDiscLaw) {
  const Lubrication law;
  const std::array<int, 6> in_plane = {0, 1, 5, 6, 7, 11};
  const std::array<int, 6> out_of_plane = {2, 3, 4, 8, 9, 10};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * kPi);
  for (const auto& [ai, aj] : kSizePairs)
    for (double h : kGaps) {
      const double theta = angle(rng);
      const Vec2 n2(std::cos(theta), std::sin(theta));
      const PairResistance r = law.coefficients(ai, aj, h);
      const Mat12 m3 = r.matrix_3d(Space3(n2.x(), n2.y(), 0.0));
      const Mat6 m2 = r.matrix(n2, perp(n2));
      Mat6 restricted;
      for (int a = 0; a < 6; ++a)
        for (int b = 0; b < 6; ++b) restricted(a, b) = m3(in_plane[a], in_plane[b]);
      EXPECT_LT(relative_difference(restricted, m2), 1e-14) << "a = " << ai << ", " << aj;
      for (int a : in_plane)
        for (int b : out_of_plane) EXPECT_EQ(m3(a, b), 0.0);
    }
}

// The law has no preferred direction: rotating the pair by Q rotates each 3-vector of the block.
TEST(Lubrication3d, TurnsWithThePair) {
  const Lubrication law;
  std::mt19937_64 rng(5);
  for (const auto& [ai, aj] : kSizePairs) {
    const Space3 n = random_unit(rng);
    const Mat3 q =
        Eigen::AngleAxisd(1.1, random_unit(rng)).toRotationMatrix();  // a proper rotation
    Mat12 b = Mat12::Zero();
    for (int k = 0; k < 4; ++k) b.block<3, 3>(3 * k, 3 * k) = q;
    const PairResistance r = law.coefficients(ai, aj, 0.02);
    EXPECT_LT(relative_difference(r.matrix_3d(q * n), b * r.matrix_3d(n) * b.transpose()), 1e-14);
  }
}

// Symmetric and positive semi-definite: it dissipates, for every gap and pair of sizes.
TEST(Lubrication3d, SymmetricAndDissipative) {
  const Lubrication law;
  for (const auto& [ai, aj] : kSizePairs)
    for (double h : kGaps) {
      const Mat12 m = law.coefficients(ai, aj, h).matrix_3d(Space3(0.6, -0.48, 0.64));
      EXPECT_LT((m - m.transpose()).norm(), 1e-14 * m.norm());
      const Eigen::SelfAdjointEigenSolver<Mat12> eig(m);
      EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-12 * m.norm());
    }
}

// At contact (r = s, the coefficients of h = 0) a rigid motion of the pair costs nothing: any
// translation, and any rotation Omega about the pair's centre (u = Omega x (x - c), omega =
// Omega). This is the identity beta_i + beta_j = s YA, gamma_ii + gamma_ij = s beta_i of the
// coefficients, now in every direction.
TEST(Lubrication3d, RigidMotionsAreFreeAtContact) {
  const Lubrication law;
  std::mt19937_64 rng(7);
  for (const auto& [ai, aj] : kSizePairs) {
    const Space3 n = random_unit(rng);
    const double s = ai + aj;
    const Space3 xi(0.3, -1.0, 2.0), xj = xi + s * n, c(-0.4, 0.9, 0.2);
    const Mat12 m = law.coefficients(ai, aj, 0.0).matrix_3d(n);
    for (int k = 0; k < 6; ++k) {
      Eigen::Matrix<double, 12, 1> u = Eigen::Matrix<double, 12, 1>::Zero();
      const Space3 e = Space3::Unit(k % 3);
      if (k < 3) {  // translation
        u.segment<3>(0) = e;
        u.segment<3>(6) = e;
      } else {  // rotation about c
        u.segment<3>(0) = e.cross(xi - c);
        u.segment<3>(3) = e;
        u.segment<3>(6) = e.cross(xj - c);
        u.segment<3>(9) = e;
      }
      EXPECT_LT((m * u).norm(), 1e-12 * m.norm()) << "motion " << k << ", a = " << ai << ", " << aj;
    }
  }
}

// Two spheres approaching along n at a gap eps feel Reynolds' squeeze force
// 6 pi eta (a_i a_j / (a_i + a_j))^2 U / eps (Jeffrey & Onishi's leading term), and no torque.
TEST(Lubrication3d, SqueezeIsReynolds) {
  Lubrication law;
  law.delta = 1e-12;  // the unregularised law
  std::mt19937_64 rng(11);
  for (const auto& [ai, aj] : kSizePairs) {
    const Space3 n = random_unit(rng);
    const double s = ai + aj, eps = 0.01, approach = 0.3;
    const double h = 2.0 * (s + eps) / s - 2.0;
    Eigen::Matrix<double, 12, 1> u = Eigen::Matrix<double, 12, 1>::Zero();
    u.segment<3>(0) = approach * n;  // i moves towards j
    const Eigen::Matrix<double, 12, 1> f = -law.coefficients(ai, aj, h).matrix_3d(n) * u;
    const double reynolds = 6.0 * kPi * std::pow(ai * aj / s, 2) * approach / eps;
    EXPECT_NEAR(-f.segment<3>(0).dot(n), reynolds, 1e-9 * reynolds);
    EXPECT_NEAR(f.segment<3>(6).dot(n), reynolds, 1e-9 * reynolds);
    EXPECT_LT(f.segment<3>(3).norm() + f.segment<3>(9).norm(), 1e-12 * reynolds);
  }
}

using Vec12 = FrictionalContact::Vec12;
const std::array<int, 6> kInPlane = {0, 1, 5, 6, 7, 11};  // (u_x, u_y, omega_z) of i and j

Vec12 random_motion(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  Vec12 u;
  for (int k = 0; k < 12; ++k) u[k] = g(rng);
  return u;
}

// A contact in the x-y plane moving in the plane: the vector spring is the disc's scalar spring
// along t = z x n, and its forces, torques and implicit stiffness are the disc law's on
// (u_x, u_y, omega_z); it exerts nothing out of the plane.
TEST(FrictionalContact3d, InThePlaneItIsTheDiscLaw) {
  const FrictionalContact law{1e4, 5e3, 0.5, true};
  std::mt19937_64 rng(13);
  for (const auto& [ai, aj] : kSizePairs) {
    const double theta = 0.7;
    const Vec2 n2(std::cos(theta), std::sin(theta));
    const double r = ai + aj - 0.003;
    const PairGeometry g2 = PairGeometry::make(r * n2, ai, aj);
    const PairGeometry3 g3 = PairGeometry3::make(Space3(r * n2.x(), r * n2.y(), 0.0), ai, aj);
    Vec12 u = random_motion(rng);
    Vec6 u2;
    for (int k : {2, 3, 4, 8, 9, 10}) u[k] = 0.0;  // in-plane motion
    for (int a = 0; a < 6; ++a) u2[a] = u[kInPlane[a]];
    const double dt = 1e-4;
    double xi2 = 1e-4;
    Space3 xi3 = xi2 * Space3(g2.t.x(), g2.t.y(), 0.0);
    xi2 += FrictionalContact::slip_rate(g2, u2) * dt;
    FrictionalContact::advance_3d(xi3, g3, u, dt);
    EXPECT_NEAR((xi3 - xi2 * Space3(g2.t.x(), g2.t.y(), 0.0)).norm(), 0.0, 1e-15);
    const Vec12 f3 = law.spring_force_3d(g3, xi3);
    const Vec6 f2 = law.spring_force(g2, xi2);
    const Mat12 k3 = law.stiffness_3d(g3, false);
    const Mat6 k2 = law.stiffness(g2, false);
    for (int a = 0; a < 6; ++a) {
      EXPECT_NEAR(f3[kInPlane[a]], f2[a], 1e-12 * f2.norm());
      for (int b = 0; b < 6; ++b)
        EXPECT_NEAR(k3(kInPlane[a], kInPlane[b]), k2(a, b), 1e-12 * k2.norm());
    }
    for (int k : {2, 3, 4, 8, 9, 10}) EXPECT_EQ(f3[k], 0.0);
  }
}

// A rigid motion of a touching pair (translation, rotation about any axis through any point)
// makes no slip, so it neither stretches the spring nor, with implicit springs, meets stiffness;
// and the spring's forces and torques balance (no net force, no net torque about the contact).
TEST(FrictionalContact3d, RigidMotionsDoNotSlip) {
  const FrictionalContact law;
  std::mt19937_64 rng(17);
  for (const auto& [ai, aj] : kSizePairs) {
    const Space3 n = random_unit(rng);
    const PairGeometry3 g = PairGeometry3::make((ai + aj) * n, ai, aj);  // r = s: touching
    const Space3 c(0.2, -0.3, 0.5);
    for (int k = 0; k < 6; ++k) {
      const Space3 e = Space3::Unit(k % 3);
      Vec12 u = Vec12::Zero();
      if (k < 3) {
        u.segment<3>(0) = u.segment<3>(6) = e;
      } else {
        u.segment<3>(0) = e.cross(Space3::Zero() - c);
        u.segment<3>(3) = e;
        u.segment<3>(6) = e.cross((ai + aj) * n - c);
        u.segment<3>(9) = e;
      }
      EXPECT_LT(FrictionalContact::slip_velocity_3d(g, u).norm(), 1e-14) << "motion " << k;
      EXPECT_LT((law.stiffness_3d(g, false) * u).norm(), 1e-10 * law.kn) << "motion " << k;
    }
    // The tangential spring's forces and torques at r = s balance: no net force, no net torque
    // about sphere i's centre (with an overlap the lever arms are the radii, as in 2D).
    Space3 stretch = random_unit(rng);
    FrictionalContact::turn_with_pair(stretch, n);
    const Vec12 f = law.spring_force_3d(g, 1e-4 * stretch);
    const Space3 xj = (ai + aj) * n;
    EXPECT_LT((f.segment<3>(0) + f.segment<3>(6)).norm(), 1e-12);
    EXPECT_LT((f.segment<3>(3) + f.segment<3>(9) + xj.cross(f.segment<3>(6))).norm(), 1e-12);
  }
}

// Coulomb's cone: a spring longer than mu kn overlap / kt is shortened along itself to the cone;
// the direction is kept; a spring inside the cone is left as it is. Turning with the pair keeps
// the spring's length and brings it into the plane normal to the new n.
TEST(FrictionalContact3d, CoulombConeAndTurning) {
  const FrictionalContact law{1e4, 5e3, 0.5, false};
  const PairGeometry3 g = PairGeometry3::make(Space3(0.0, 0.0, 0.99), 0.5, 0.5);  // overlap 0.01
  const double cap = 0.5 * 1e4 * 0.01 / 5e3;
  Space3 xi(3.0 * cap, 4.0 * cap, 0.0);
  EXPECT_TRUE(law.apply_coulomb_3d(g, xi));
  EXPECT_NEAR(xi.norm(), cap, 1e-15);
  EXPECT_NEAR(xi.x() / xi.y(), 0.75, 1e-14);
  Space3 inside(0.1 * cap, 0.0, 0.0);
  EXPECT_FALSE(law.apply_coulomb_3d(g, inside));
  EXPECT_EQ(inside.x(), 0.1 * cap);
  Space3 spring(1e-3, 0.0, 0.0);
  const Space3 tilted = Space3(0.3, 0.0, 1.0).normalized();
  FrictionalContact::turn_with_pair(spring, tilted);
  EXPECT_NEAR(spring.norm(), 1e-3, 1e-18);
  EXPECT_NEAR(spring.dot(tilted), 0.0, 1e-18);
}

// A sliding spring (contact.sliding_stiffness): with "none" it has no tangential stiffness;
// with "sideways" a slip along its stretch meets none (Coulomb holds the force there) and a slip
// across it meets kt times the share its last cap left, cap / |trial stretch| (1 when it
// stuck). A sticking spring meets kt either way.
TEST(FrictionalContact3d, SlidingSpringIsStiffOnlyAcrossItsStretch) {
  FrictionalContact none{1e4, 5e3, 0.5, false};
  FrictionalContact sideways = none;
  sideways.sideways = true;
  std::mt19937_64 rng(19);
  for (const auto& [ai, aj] : kSizePairs) {
    const Space3 n = random_unit(rng);
    const PairGeometry3 g = PairGeometry3::make((ai + aj - 0.01) * n, ai, aj);
    const double cap = 0.5 * 1e4 * 0.01 / 5e3;
    TangentialSpring3 spring;
    spring.xi = 3.0 * cap * random_unit(rng);
    FrictionalContact::turn_with_pair(spring.xi, n);
    sideways.cap(spring, g);
    ASSERT_TRUE(spring.sliding);
    EXPECT_NEAR(spring.across, 1.0 / 3.0, 1e-12);
    const Space3 along = spring.xi.normalized(), across = n.cross(along);
    // Sphere i translating along e: the slip is -e, normal to n.
    const auto moving = [](const Space3& e) {
      Vec12 u = Vec12::Zero();
      u.segment<3>(0) = e;
      return u;
    };
    const auto work = [&](const FrictionalContact& law, bool sliding, const Space3& e) {
      return moving(e).dot(law.stiffness_3d(g, sliding, spring.xi, spring.across) * moving(e));
    };
    EXPECT_NEAR(work(sideways, true, along), 0.0, 1e-9);
    EXPECT_NEAR(work(sideways, true, across), 5e3 / 3.0, 1e-9);
    EXPECT_NEAR(work(none, true, across), 0.0, 1e-9);
    for (const auto* law : {&none, &sideways}) {
      EXPECT_NEAR(work(*law, false, along), 5e3, 1e-9);
      EXPECT_NEAR(work(*law, false, across), 5e3, 1e-9);
    }
    // Inside the cone it sticks, and a later slide starts from the full stiffness.
    spring.xi *= 0.5;
    sideways.cap(spring, g);
    EXPECT_FALSE(spring.sliding);
    EXPECT_EQ(spring.across, 1.0);
  }
}

// Which sliding contacts stick once the step's slip s is solved (contact.stick_rule). The
// stretch xi is at the cap; its trial value xi + s dt is inside the cone when shorter than xi.
TEST(FrictionalContact3d, StickRules) {
  FrictionalContact unloading{1e4, 5e3, 0.5, false};
  FrictionalContact coulomb = unloading;
  coulomb.stick_rule = FrictionalContact::StickRule::Coulomb;
  const double cap = 1e-3, dt = 0.1;
  const Space3 xi(cap, 0.0, 0.0);
  const auto slip = [&](double along, double sideways) {  // displacement over dt, in caps
    return Space3(along * cap / dt, sideways * cap / dt, 0.0);
  };
  // Turned sideways, slightly unloaded: outside the cone (|(0.8, 1.0)| > 1), no reversal
  // through zero. Unloading sticks it (the spheres' extra switches); Coulomb leaves it sliding.
  EXPECT_TRUE(unloading.sticks_3d(xi, slip(-0.2, 1.0), dt));
  EXPECT_FALSE(coulomb.sticks_3d(xi, slip(-0.2, 1.0), dt));
  // Inside the cone: both stick.
  EXPECT_TRUE(unloading.sticks_3d(xi, slip(-0.5, 0.3), dt));
  EXPECT_TRUE(coulomb.sticks_3d(xi, slip(-0.5, 0.3), dt));
  // Through zero along xi, though outside the cone: both stick (left sliding it would flip to
  // the opposite cap).
  EXPECT_TRUE(coulomb.sticks_3d(xi, slip(-1.5, 2.0), dt));
  // Loading further: neither.
  EXPECT_FALSE(unloading.sticks_3d(xi, slip(0.5, 1.0), dt));
  EXPECT_FALSE(coulomb.sticks_3d(xi, slip(0.5, 1.0), dt));
  // Slip along xi, as between discs: the two rules are one, at every reversal (below twice the
  // cap inside the cone, beyond it through zero).
  for (const double a : {1e-6, 0.1, 0.99, 1.0, 1.5, 1.99, 2.0, 2.5, 10.0, 1e6}) {
    EXPECT_TRUE(coulomb.sticks_3d(xi, slip(-a, 0.0), dt)) << a;
    EXPECT_TRUE(unloading.sticks_3d(xi, slip(-a, 0.0), dt)) << a;
    EXPECT_FALSE(coulomb.sticks_3d(xi, slip(a, 0.0), dt)) << a;
  }
}

}  // namespace
}  // namespace sheardiff
