#include "sheardiff/solver/sparse_cholesky.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <stdexcept>

// OpenBLAS (behind CHOLMOD's supernodal kernels) would start one thread per core; sheardiff
// runs one process per core in sweeps, so its BLAS stays single-threaded. Weak: absent with
// other BLAS implementations.
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace sheardiff {

namespace {

template <class Solver>
class EigenBacked final : public SparseCholesky {
 public:
  explicit EigenBacked(const char* name) : name_(name) {}
  void analyze(const Eigen::SparseMatrix<double>& lower) override { solver_.analyzePattern(lower); }
  bool factorize(const Eigen::SparseMatrix<double>& lower) override {
    solver_.factorize(lower);
    return solver_.info() == Eigen::Success;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const override { return solver_.solve(rhs); }
  const char* name() const override { return name_; }

 protected:
  Solver solver_;
  const char* name_;
};

class Cholmod final : public SparseCholesky {
 public:
  Cholmod() {
    if (openblas_set_num_threads) openblas_set_num_threads(1);
  }
  void analyze(const Eigen::SparseMatrix<double>& lower) override { solver_.analyzePattern(lower); }
  bool factorize(const Eigen::SparseMatrix<double>& lower) override {
    solver_.factorize(lower);
    return solver_.info() == Eigen::Success;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const override { return solver_.solve(rhs); }
  const char* name() const override { return "cholmod"; }

 private:
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> solver_;
};

}  // namespace

std::unique_ptr<SparseCholesky> make_sparse_cholesky(const std::string& kind) {
  if (kind == "cholmod") return std::make_unique<Cholmod>();
  if (kind == "eigen")
    return std::make_unique<
        EigenBacked<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower>>>("eigen");
  throw std::invalid_argument("unknown sparse Cholesky '" + kind + "'");
}

}  // namespace sheardiff
