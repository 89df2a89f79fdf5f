#pragma once
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <memory>
#include <string>

namespace sheardiff {

// A sparse Cholesky factorisation of the lower triangle of an SPD matrix, with the symbolic
// analysis kept between factorisations of matrices of the same pattern.
class SparseCholesky {
 public:
  virtual ~SparseCholesky() = default;
  virtual void analyze(const Eigen::SparseMatrix<double>& lower) = 0;
  // False if the matrix is not positive definite.
  virtual bool factorize(const Eigen::SparseMatrix<double>& lower) = 0;
  virtual Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const = 0;
  // Several right-hand sides as one block: CHOLMOD's supernodal solve then runs matrix-matrix
  // kernels, several times cheaper per column than one-by-one solves (bench_solver's
  // cholmod_spheres_columns_*).
  virtual Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const = 0;
  virtual const char* name() const = 0;
  // Back-substitutions that cost as much as one factorisation of the analysed pattern, from
  // the analysis' flop counts (0: unknown).
  virtual double solves_per_factorisation() const { return 0.0; }
};

// "cholmod": CHOLMOD supernodal LLT (SuiteSparse; fastest, see docs/performance.md), tuned for
// the matrices of discs (dimension 2) or spheres (3); "eigen": Eigen's SimplicialLLT.
std::unique_ptr<SparseCholesky> make_sparse_cholesky(const std::string& kind, int dimension = 2);

}  // namespace sheardiff
