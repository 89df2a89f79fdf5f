// The pre-permuted CHOLMOD path (src/solver/sparse_cholesky.cpp) against CHOLMOD permuting
// the matrix itself: the same fill-reducing ordering and supernodes, so the same factor and the
// same solutions, to the last bit.
#include <gtest/gtest.h>

#include <Eigen/CholmodSupport>

#include "sheardiff/run.hpp"
#include "sheardiff/solver/detail/cholmod_tuning.hpp"
#include "sheardiff/solver/sparse_cholesky.hpp"

namespace sheardiff {
namespace {

TEST(SparseCholesky, PrePermutedSameAsCholmodPermuting) {
  for (const char* scene : {"simple_shear", "pressure_shear"}) {
    Config cfg;
    cfg.scene.type = scene;
    cfg.particles.n = 250;
    cfg.particles.phi_init = 0.77;
    cfg.flow.j = 1e-2;
    cfg.contact.ktilde = 1e4;
    Simulation sim(cfg);
    for (int k = 0; k < 30; ++k) sim.step();
    const auto& a = sim.dynamics().force_balance().system().matrix();
    const Eigen::VectorXd rhs = sim.dynamics().force_balance().system().rhs();

    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> reference;
    tune_cholmod(reference.cholmod());
    reference.analyzePattern(a);
    reference.factorize(a);
    const Eigen::VectorXd x_ref = reference.solve(rhs);

    auto chol = make_sparse_cholesky("cholmod");
    chol->analyze(a);
    ASSERT_TRUE(chol->factorize(a));
    const Eigen::VectorXd x = chol->solve(rhs);
    // Bit for bit: any other ordering or supernode partition would change the rounding.
    EXPECT_EQ((x - x_ref).cwiseAbs().maxCoeff(), 0.0) << scene;
    // And a second factorisation of new values on the same pattern (what every step does).
    Eigen::SparseMatrix<double> b = a;
    for (Eigen::Index k = 0; k < b.outerSize(); ++k) b.coeffRef(k, k) *= 1.5;
    reference.factorize(b);
    ASSERT_TRUE(chol->factorize(b));
    EXPECT_EQ((chol->solve(rhs) - reference.solve(rhs)).cwiseAbs().maxCoeff(), 0.0) << scene;
    EXPECT_GT((chol->solve(rhs) - x).cwiseAbs().maxCoeff(), 0.0) << "new values not read";
  }
}

// The matrix and right-hand side of 150 spheres in the pressure cell after 10 steps.
struct SpheresSystem {
  Eigen::SparseMatrix<double> a;
  Eigen::VectorXd rhs;
};
SpheresSystem sheared_spheres() {
  Config cfg;
  cfg.scene.type = "pressure_shear";
  cfg.scene.dimension = 3;
  cfg.particles.n = 150;
  cfg.particles.phi_init_spheres = 0.5;
  cfg.flow.j = 1e-2;
  cfg.contact.ktilde = 1e4;
  Simulation3 sim(cfg);
  for (int k = 0; k < 10; ++k) sim.step();
  const auto& system = sim.dynamics().force_balance().system();
  return {system.matrix(), system.rhs()};
}

// Spheres: their own tuning (CHOLMOD's supernode relaxation), the same two paths.
TEST(SparseCholesky, PrePermutedSameAsCholmodPermutingForSpheres) {
  const auto [a, rhs] = sheared_spheres();
  ASSERT_GT(a.nonZeros(), 6 * a.rows()) << "the test needs coupled spheres";

  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> reference;
  tune_cholmod(reference.cholmod(), 3);
  reference.analyzePattern(a);
  reference.factorize(a);
  auto chol = make_sparse_cholesky("cholmod", 3);
  chol->analyze(a);
  ASSERT_TRUE(chol->factorize(a));
  EXPECT_EQ((chol->solve(rhs) - reference.solve(rhs)).cwiseAbs().maxCoeff(), 0.0);
  // The discs' tuning partitions the same matrix into fewer, larger supernodes (more explicit
  // zeros): the spheres' tuning is a different factorisation, not a relabelled one. Read from
  // the symbolic factors, which do not depend on the BLAS's rounding.
  SupernodalWithFactor spheres, discs;
  tune_cholmod(spheres.cholmod(), 3);
  tune_cholmod(discs.cholmod(), 2);
  spheres.analyzePattern(a);
  discs.analyzePattern(a);
  ASSERT_TRUE(spheres.factor()->is_super && discs.factor()->is_super);
  EXPECT_LT(discs.factor()->nsuper, spheres.factor()->nsuper);
  EXPECT_GT(discs.factor()->xsize, spheres.factor()->xsize);
}

// The Woodbury columns of a sticking re-solve are solved as one block: each column of the
// block is the solution of that column alone, for both back-ends. The block kernels may round
// differently from the one-column ones, hence a relative tolerance (1e-10: far above the
// round-off, far below the O(1) error of a misplaced permutation or column).
TEST(SparseCholesky, BlockSolveIsTheColumnsSolvedOneByOne) {
  const auto [a, rhs] = sheared_spheres();
  const Eigen::Index n = a.rows(), k = 7;
  // Sparse columns like a contact's tangential rows, and one dense column.
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(n, k);
  for (Eigen::Index c = 0; c + 1 < k; ++c)
    for (Eigen::Index r = 0; r < 12; ++r) w((c * 97 + r * 31) % n, c) = 1.0 / (1.0 + r);
  w.col(k - 1) = rhs;
  for (const char* kind : {"cholmod", "eigen"}) {
    auto chol = make_sparse_cholesky(kind, 3);
    chol->analyze(a);
    ASSERT_TRUE(chol->factorize(a));
    const Eigen::MatrixXd z = chol->solve(w);
    ASSERT_EQ(z.rows(), n);
    ASSERT_EQ(z.cols(), k);
    for (Eigen::Index c = 0; c < k; ++c) {
      const Eigen::VectorXd one = chol->solve(Eigen::VectorXd(w.col(c)));
      EXPECT_LE((z.col(c) - one).norm(), 1e-10 * one.norm()) << kind << " column " << c;
      // And it solves A z = w (the permutation is undone row by row).
      const Eigen::VectorXd az = a.selfadjointView<Eigen::Lower>() * z.col(c);
      EXPECT_LE((az - w.col(c)).norm(), 1e-8 * w.col(c).norm()) << kind << " column " << c;
    }
  }
}

}  // namespace
}  // namespace sheardiff
