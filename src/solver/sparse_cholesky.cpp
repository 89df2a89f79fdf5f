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
    tune_cholmod(solver_.cholmod());
  }
  void analyze(const Eigen::SparseMatrix<double>& lower) override {
    solver_.analyzePattern(lower);
    if (solver_.cholmod().status == CHOLMOD_NOT_INSTALLED) {
      // A CHOLMOD built without METIS has no nested dissection: fall back to its default (AMD).
      solver_.cholmod().nmethods = 0;
      solver_.analyzePattern(lower);
    }
    // fl / (4 lnz) is the flop ratio; the factorisation's dense BLAS-3 kernels run ~3x faster
    // per flop than the triangular solves (bench_step: 2.5 ms against 0.17 ms at N = 1000,
    // 15 ms against 0.9 ms at N = 4000, i.e. 15-16 solves per factorisation).
    const cholmod_common& c = solver_.cholmod();
    solves_per_factorisation_ = c.lnz > 0.0 ? c.fl / (12.0 * c.lnz) : 0.0;
  }
  bool factorize(const Eigen::SparseMatrix<double>& lower) override {
    solver_.factorize(lower);
    return solver_.info() == Eigen::Success;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const override { return solver_.solve(rhs); }
  const char* name() const override { return "cholmod"; }
  double solves_per_factorisation() const override { return solves_per_factorisation_; }

 private:
  using Solver = Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
  Solver solver_;
  double solves_per_factorisation_ = 0.0;  // from the last analysis
};

}  // namespace

void tune_cholmod(cholmod_common& c) {
  // The matrix is the contact graph of a 2D packing: nested dissection (CHOLMOD's NESDIS) gives
  // 20-27% fewer factorisation flops than AMD, and supernodes relaxed twice as far as CHOLMOD's
  // defaults trade a few explicit zeros for fewer, larger BLAS calls. Together -19% per
  // factorisation at N = 1000 and 4000 (bench/bench_solver, docs/performance.md); the costlier
  // analysis is paid once per neighbour rebuild.
  c.nmethods = 1;
  c.method[0].ordering = CHOLMOD_NESDIS;
  for (int k = 1; k < 3; ++k) {
    c.nrelax[k] *= 2;
    c.zrelax[k] *= 2.0;
  }
  c.nrelax[0] *= 2;
}

std::unique_ptr<SparseCholesky> make_sparse_cholesky(const std::string& kind) {
  if (kind == "cholmod") return std::make_unique<Cholmod>();
  if (kind == "eigen")
    return std::make_unique<
        EigenBacked<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower>>>("eigen");
  throw std::invalid_argument("unknown sparse Cholesky '" + kind + "'");
}

}  // namespace sheardiff
