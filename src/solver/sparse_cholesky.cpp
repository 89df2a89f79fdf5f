#include "sheardiff/solver/sparse_cholesky.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <stdexcept>
#include <vector>

#include "sheardiff/solver/detail/cholmod_tuning.hpp"

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
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const override { return solver_.solve(rhs); }
  const char* name() const override { return name_; }

 protected:
  Solver solver_;
  const char* name_;
};

// CHOLMOD factorises tril(P A P^T). Given the lower triangle of A and a fill-reducing P, it
// forms that matrix with two symmetric transposes before every factorisation
// (cholmod_transpose_sym: 7-10 % of a run's time in perf). Here the ordering is computed once
// per analysis, A's values are scattered straight into tril(P A P^T) through a map, and that
// matrix is factorised with CHOLMOD's natural ordering, which takes a lower triangle as it is.
// Same matrix, same supernodes, same arithmetic: the solutions are those of the permuting path
// to the last bit (tests/unit/test_sparse_cholesky.cpp), and factorise + solve take 9-15 % less
// time (bench_solver: sheardiff_cholmod against cholmod_supernodal_tuned).
class Cholmod final : public SparseCholesky {
 public:
  explicit Cholmod(int dimension) {
    set_blas_threads(1);
    tune_cholmod(ordering_.cholmod(), dimension);
    // Only its P is used: a simplicial analysis orders and postorders the same way and skips
    // the supernodal symbolic factor that natural_ computes anyway.
    ordering_.cholmod().supernodal = CHOLMOD_SIMPLICIAL;
    tune_cholmod(natural_.cholmod(), dimension);
    natural_.cholmod().nmethods = 1;
    natural_.cholmod().method[0].ordering = CHOLMOD_NATURAL;
    // P already holds CHOLMOD's postorder of the elimination tree.
    natural_.cholmod().postorder = 0;
  }
  void analyze(const Eigen::SparseMatrix<double>& lower) override {
    ordering_.analyzePattern(lower);
    if (ordering_.cholmod().status == CHOLMOD_NOT_INSTALLED) {
      // A CHOLMOD built without METIS has no nested dissection: fall back to its default (AMD).
      ordering_.cholmod().nmethods = 0;
      ordering_.analyzePattern(lower);
    }
    const cholmod_factor* f = ordering_.factor();
    const auto n = static_cast<Eigen::Index>(f->n);
    const int* perm = static_cast<const int*>(f->Perm);
    perm_.resize(n);
    Eigen::VectorXi inverse(n);
    for (Eigen::Index k = 0; k < n; ++k) {
      perm_[k] = perm[k];
      inverse[perm[k]] = static_cast<int>(k);
    }
    // The pattern of tril(P A P^T); each entry's value is its index in A's value array, read
    // back after compression as the scatter map.
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<std::size_t>(lower.nonZeros()));
    for (Eigen::Index c = 0; c < lower.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(lower, c); it; ++it) {
        const int i = inverse[it.row()], j = inverse[it.col()];
        t.emplace_back(std::max(i, j), std::min(i, j),
                       static_cast<double>(&it.value() - lower.valuePtr()));
      }
    permuted_.resize(n, n);
    permuted_.setFromTriplets(t.begin(), t.end());
    permuted_.makeCompressed();
    to_permuted_.resize(static_cast<std::size_t>(lower.nonZeros()));
    for (Eigen::Index e = 0; e < permuted_.nonZeros(); ++e)
      to_permuted_[static_cast<std::size_t>(permuted_.valuePtr()[e])] = e;
    natural_.analyzePattern(permuted_);
    // fl / (4 lnz) is the flop ratio; the factorisation's dense BLAS-3 kernels run ~3x faster
    // per flop than the triangular solves (bench_step: 2.5 ms against 0.17 ms at N = 1000,
    // 15 ms against 0.9 ms at N = 4000, i.e. 15-16 solves per factorisation).
    const cholmod_common& c = natural_.cholmod();
    solves_per_factorisation_ = c.lnz > 0.0 ? c.fl / (12.0 * c.lnz) : 0.0;
  }
  bool factorize(const Eigen::SparseMatrix<double>& lower) override {
    const double* a = lower.valuePtr();
    double* b = permuted_.valuePtr();
    for (std::size_t e = 0; e < to_permuted_.size(); ++e) b[to_permuted_[e]] = a[e];
    natural_.factorize(permuted_);
    return natural_.info() == Eigen::Success;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) const override { return permuted_solve(rhs); }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& rhs) const override { return permuted_solve(rhs); }
  const char* name() const override { return "cholmod"; }
  double solves_per_factorisation() const override { return solves_per_factorisation_; }

 private:
  // P A P^T (P x) = P b: the rows of the right-hand sides in, the solution's rows back.
  template <class Dense>
  Dense permuted_solve(const Dense& rhs) const {
    Dense x(rhs.rows(), rhs.cols());
    for (Eigen::Index k = 0; k < rhs.rows(); ++k) x.row(k) = rhs.row(perm_[k]);
    const Dense y = natural_.solve(x);
    for (Eigen::Index k = 0; k < rhs.rows(); ++k) x.row(perm_[k]) = y.row(k);
    return x;
  }

  SupernodalWithFactor ordering_;  // analysis only: the fill-reducing P
  Supernodal natural_;             // factorises tril(P A P^T) as given
  Eigen::VectorXi perm_;           // P: row k of P A P^T is row perm_[k] of A
  Eigen::SparseMatrix<double> permuted_;
  std::vector<Eigen::Index> to_permuted_;  // A's value e goes to permuted_'s to_permuted_[e]
  double solves_per_factorisation_ = 0.0;  // from the last analysis
};

}  // namespace

void set_blas_threads(int threads) {
  if (openblas_set_num_threads) openblas_set_num_threads(threads);
}

void tune_cholmod(cholmod_common& c, int dimension) {
  // The matrix is the contact graph of a packing: for discs nested dissection (CHOLMOD's NESDIS)
  // gives 20-27% fewer factorisation flops than AMD, and supernodes relaxed twice as far as
  // CHOLMOD's defaults trade a few explicit zeros for fewer, larger BLAS calls. Together -13 % and
  // -11 % per factorisation at N = 1000 and 4000 (bench/bench_solver, docs/performance.md); the
  // costlier analysis is paid once per neighbour rebuild. A packing of spheres has larger
  // separators, so its supernodes are large already: relaxing them further only adds zeros
  // (7-16 % slower at N = 1000, 9 % at 2000, bench_solver's cholmod_spheres), so spheres keep
  // CHOLMOD's relaxation.
  c.nmethods = 1;
  c.method[0].ordering = CHOLMOD_NESDIS;
  if (dimension == 3) return;
  for (int k = 1; k < 3; ++k) {
    c.nrelax[k] *= 2;
    c.zrelax[k] *= 2.0;
  }
  c.nrelax[0] *= 2;
}

std::unique_ptr<SparseCholesky> make_sparse_cholesky(const std::string& kind, int dimension) {
  if (kind == "cholmod") return std::make_unique<Cholmod>(dimension);
  if (kind == "eigen")
    return std::make_unique<
        EigenBacked<Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower>>>("eigen");
  throw std::invalid_argument("unknown sparse Cholesky '" + kind + "'");
}

}  // namespace sheardiff
