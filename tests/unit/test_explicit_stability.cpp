// The explicit integrators' stability limit (PairLaws::explicit_stability_dt, docs/model.md
// section 7) against the exact fastest rate of the packings that relax fastest: the periodic
// triangular lattice of small discs and the periodic FCC lattice of small spheres, every pair at
// contact (h = 0), with the laws' own blocks. Explicit Euler on R u = -K x is stable while
// lambda_max dt < 2, lambda_max the largest eigenvalue of K v = lambda R v (R: Stokes drag plus
// the lubrication blocks, K: the springs' stiffness with every contact sticking, the stiffest
// case). These are the densest networks of the smallest pair, each particle at its kissing
// number; the limit was first taken from a lone pair, which the lattices relax 1.5 times
// (lubricated) to 8 times (drag-bound) faster than, and without lubrication a dense explicit run
// at the default step gave a shear stress 100 times too small (docs/journal.md).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "sheardiff/engine.hpp"
#include "sheardiff/interactions/contact.hpp"
#include "sheardiff/interactions/lubrication.hpp"
#include "sheardiff/interactions/pair_geometry.hpp"
#include "sheardiff/interactions/stokes_drag.hpp"

namespace sheardiff {
namespace {

struct Lattice {
  std::vector<Space3> centres;
  Space3 box;  // periodic edges
  int dimension;
};

// Triangular lattice of unit spacing, 6 x 6 discs in a periodic box.
Lattice triangular() {
  Lattice l{{}, Space3(6.0, 6.0 * std::sqrt(3.0) / 2.0, 0.0), 2};
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i)
      l.centres.emplace_back(i + 0.5 * (j % 2), j * std::sqrt(3.0) / 2.0, 0.0);
  return l;
}

// FCC lattice of unit nearest-neighbour distance, 2 x 2 x 2 cubic cells (32 spheres), periodic.
Lattice fcc() {
  const double a = std::sqrt(2.0);
  Lattice l{{}, Space3(2.0 * a, 2.0 * a, 2.0 * a), 3};
  const Space3 basis[] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int x = 0; x < 2; ++x)
    for (int y = 0; y < 2; ++y)
      for (int z = 0; z < 2; ++z)
        for (const Space3& b : basis) l.centres.push_back(a * (b + Space3(x, y, z)));
  return l;
}

// Largest rate of explicit Euler on the lattice: the unknowns are (u, omega) of every particle,
// (u_x, u_y, omega_z) for discs.
double fastest_rate(const Lattice& l, const std::optional<Lubrication>& lub,
                    const FrictionalContact& contact) {
  const int n = static_cast<int>(l.centres.size());
  const int per = l.dimension == 3 ? 6 : 3;
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(per * n, per * n), k = r;
  const double a = 0.5;
  for (int i = 0; i < n; ++i) {
    if (l.dimension == 3)
      r.block<6, 6>(per * i, per * i) += StokesDrag::resistance_3d(a).asDiagonal().toDenseMatrix();
    else
      r.block<3, 3>(per * i, per * i) += StokesDrag::resistance(a).asDiagonal().toDenseMatrix();
  }
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      Space3 d = l.centres[j] - l.centres[i];
      for (int c = 0; c < l.dimension; ++c) d[c] -= l.box[c] * std::round(d[c] / l.box[c]);
      if (d.norm() > 1.0 + 1e-9) continue;
      Eigen::MatrixXd rp, kp;
      if (l.dimension == 3) {
        const PairGeometry3 g = PairGeometry3::make(d, a, a);
        rp = lub ? Eigen::MatrixXd(lub->coefficients(a, a, 0.0).matrix_3d(g.n))
                 : Eigen::MatrixXd::Zero(12, 12);
        kp = contact.stiffness_3d(g, false);
      } else {
        const PairGeometry g = PairGeometry::make(Vec2(d.x(), d.y()), a, a);
        rp = lub ? Eigen::MatrixXd(lub->coefficients(a, a, 0.0).matrix(g.n, g.t))
                 : Eigen::MatrixXd::Zero(6, 6);
        kp = contact.stiffness(g, false);
      }
      const int idx[2] = {per * i, per * j};
      for (int p = 0; p < 2; ++p)
        for (int q = 0; q < 2; ++q) {
          r.block(idx[p], idx[q], per, per) += rp.block(per * p, per * q, per, per);
          k.block(idx[p], idx[q], per, per) += kp.block(per * p, per * q, per, per);
        }
    }
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(k, r, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().maxCoeff();
}

enum class Lubricated { No, SqueezeOnly, Yes };

Config config(int dimension, Lubricated lubricated, double kt_ratio) {
  Config c;
  c.scene.dimension = dimension;
  c.lubrication.enabled = lubricated != Lubricated::No;
  c.lubrication.tangential = lubricated == Lubricated::Yes;
  c.contact.ktilde = 1e4;
  c.contact.kt_ratio = kt_ratio;
  c.contact.mu = kt_ratio > 0.0 ? 0.5 : 0.0;
  return c;
}

// For every law mix the limit is stable on the lattice (lambda dt_stab <= 2) and not needlessly
// small (lambda dt_stab >= 0.85: the drag-bound normal mode of spheres is the most conservative
// case, 0.89); the default explicit_safety keeps lambda dt below 1 (0.99 at most). Lubrication
// with its squeeze mode only leaves the slip mode drag-bound, as no lubrication does.
TEST(ExplicitStability, TheLimitHoldsOnTheDensestLattices) {
  for (const Lattice& l : {triangular(), fcc()})
    for (Lubricated lubricated : {Lubricated::Yes, Lubricated::SqueezeOnly, Lubricated::No})
      for (double kt_ratio : {0.0, 0.1, 2.0 / 7.0, 0.5, 1.0, 2.0}) {
        const Config c = config(l.dimension, lubricated, kt_ratio);
        const FrictionalContact contact{c.contact.ktilde, kt_ratio * c.contact.ktilde, c.contact.mu,
                                        false};
        const std::optional<Lubrication> lub = Lubrication::from(c);
        const double rate = fastest_rate(l, lub, contact);
        const double dt = explicit_stability_dt(c);
        SCOPED_TRACE(testing::Message() << "dimension " << l.dimension << ", lubrication "
                                        << static_cast<int>(lubricated) << ", kt/kn " << kt_ratio
                                        << ": lambda " << rate << ", dt_stab " << dt);
        EXPECT_LE(rate * dt, 2.0);
        EXPECT_GE(rate * dt, 0.85);
        EXPECT_LT(rate * c.integrator.explicit_safety * dt, 1.0);
      }
}

// The case that went wrong: discs without lubrication, friction on. The lone pair's limit,
// 2 (3 pi d / 2) / kt, is 3.5 times what the triangular lattice allows.
TEST(ExplicitStability, ALonePairIsNotTheFastestMode) {
  const Config c = config(2, Lubricated::No, 0.5);
  const FrictionalContact contact{1e4, 5e3, 0.5, false};
  const double lone_pair = 2.0 * (3.0 * kPi / 2.0) / 5e3;
  const double rate = fastest_rate(triangular(), std::nullopt, contact);
  EXPECT_GT(rate * lone_pair, 2.0 * 3.4);
  EXPECT_LE(rate * explicit_stability_dt(c), 2.0);
}

}  // namespace
}  // namespace sheardiff
