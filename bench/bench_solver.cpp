// Solver choice for the per-step SPD system (issue "fast and accurate"): factorise the matrix of
// a dense sheared packing (simple shear, phi = 0.77, ktilde = 1e4, implicit springs) with each
// candidate. Prints time per factorisation + solve; the symbolic analysis is done once, as in a
// run between neighbour rebuilds.
//
//   build/bench/bench_solver --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <map>
#include <memory>

#ifdef SHEARDIFF_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include "sheardiff/simulation.hpp"
#include "sheardiff/solver/sparse_cholesky.hpp"

namespace {

struct Problem {
  Eigen::SparseMatrix<double> lower;  // lower triangle, as assembled
  Eigen::SparseMatrix<double> full;
  Eigen::VectorXd rhs;
};

const Problem& problem(int n) {
  static std::map<int, Problem> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  sheardiff::Config cfg;
  cfg.particles.n = n;
  cfg.particles.phi_init = 0.77;
  cfg.flow.j = 1e-2;
  cfg.contact.ktilde = 1e4;
  sheardiff::Simulation sim(cfg);
  for (int k = 0; k < 30; ++k) sim.step();
  Problem p;
  const auto& rs = sim.dynamics().force_balance().system();
  p.lower = rs.matrix();
  p.full = p.lower.selfadjointView<Eigen::Lower>();
  p.rhs = rs.rhs();
  return cache.emplace(n, std::move(p)).first->second;
}

// Times factorisation + solve of an analysed solver and sets the counters every variant prints.
template <class Solver>
void time_factorise(benchmark::State& state, const Problem& p, Solver& solver) {
  solver.analyzePattern(p.lower);
  Eigen::VectorXd x;
  for (auto _ : state) {
    solver.factorize(p.lower);
    x = solver.solve(p.rhs);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["unknowns"] = static_cast<double>(p.lower.rows());
  state.counters["nnz_lower"] = static_cast<double>(p.lower.nonZeros());
  state.counters["rel_residual"] = (p.full * x - p.rhs).norm() / p.rhs.norm();
}

template <class Solver>
void factorise(benchmark::State& state) {
  Solver solver;
  time_factorise(state, problem(static_cast<int>(state.range(0))), solver);
}

using LLT = Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
using LDLT = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
BENCHMARK(factorise<LLT>)
    ->Name("eigen_simplicial_llt")
    ->Arg(250)
    ->Arg(1000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(factorise<LDLT>)
    ->Name("eigen_simplicial_ldlt")
    ->Arg(250)
    ->Arg(1000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond);
#ifdef SHEARDIFF_HAVE_CHOLMOD
using Supernodal = Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;

// CHOLMOD supernodal with CHOLMOD's defaults (AMD; named cholmod_supernodal_llt in the first
// solver table of docs/performance.md) or with sheardiff's settings
// (tune_cholmod: nested dissection, relaxed supernodes), with the flop count of the
// factorisation and the non-zeros of the factor, the floor any exact solve pays.
template <bool Tuned>
void cholmod_supernodal(benchmark::State& state) {
  Supernodal solver;
  if (Tuned) sheardiff::tune_cholmod(solver.cholmod());
  time_factorise(state, problem(static_cast<int>(state.range(0))), solver);
  const double flops = solver.cholmod().fl;
  state.counters["nnz_L"] = solver.cholmod().lnz;
  state.counters["Mflop"] = flops / 1e6;
  state.counters["GFlop/s"] =
      benchmark::Counter(flops / 1e9, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(cholmod_supernodal<false>)
    ->Name("cholmod_supernodal_amd")
    ->Arg(250)
    ->Arg(1000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(cholmod_supernodal<true>)
    ->Name("cholmod_supernodal_tuned")
    ->Arg(250)
    ->Arg(1000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond);
// sheardiff's CHOLMOD path (make_sparse_cholesky("cholmod"): the matrix scattered into
// tril(P A P^T) and factorised with the natural ordering) against cholmod_supernodal_tuned
// above (CHOLMOD permuting it with two symmetric transposes per factorisation).
void sheardiff_cholmod(benchmark::State& state) {
  const Problem& p = problem(static_cast<int>(state.range(0)));
  auto solver = sheardiff::make_sparse_cholesky("cholmod");
  solver->analyze(p.lower);
  Eigen::VectorXd x;
  for (auto _ : state) {
    solver->factorize(p.lower);
    x = solver->solve(p.rhs);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["rel_residual"] = (p.full * x - p.rhs).norm() / p.rhs.norm();
}
BENCHMARK(sheardiff_cholmod)->Arg(250)->Arg(1000)->Arg(4000)->Unit(benchmark::kMillisecond);

// Back-substitutions of the low-rank sticking re-solve (ResistanceSystem::apply_inverse): k
// columns, each the slip mode of one contact (6 non-zeros), solved one by one (as sheardiff
// does) or as one k-column block on the tuned supernodal factor. Compare time per column with
// cholmod_supernodal_tuned's factorisation: that ratio bounds the budget of low_rank_pays
// (docs/performance.md, "Block columns for the sticking re-solve": measured not to pay in runs).
template <bool Block>
void cholmod_low_rank_columns(benchmark::State& state) {
  const Problem& p = problem(static_cast<int>(state.range(0)));
  const auto k = static_cast<Eigen::Index>(state.range(1));
  Supernodal solver;
  sheardiff::tune_cholmod(solver.cholmod());
  solver.analyzePattern(p.lower);
  solver.factorize(p.lower);
  const Eigen::Index n = p.lower.rows();
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(n, k);
  for (Eigen::Index c = 0; c < k; ++c)
    for (Eigen::Index r = 0; r < 6; ++r) w((c * 97 + r * (n / 7)) % n, c) = 1.0 / (1.0 + r);
  Eigen::MatrixXd z(n, k);
  for (auto _ : state) {
    if (Block) {
      z = solver.solve(w);
    } else {
      for (Eigen::Index c = 0; c < k; ++c) z.col(c) = solver.solve(Eigen::VectorXd(w.col(c)));
    }
    benchmark::DoNotOptimize(z.data());
  }
  state.counters["us_per_column"] = benchmark::Counter(
      static_cast<double>(k) * 1e-6,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(cholmod_low_rank_columns<false>)
    ->Name("cholmod_columns_one_by_one")
    ->ArgsProduct({{1000, 4000}, {1, 8, 32, 64}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(cholmod_low_rank_columns<true>)
    ->Name("cholmod_columns_block")
    ->ArgsProduct({{1000, 4000}, {1, 8, 32, 64}})
    ->Unit(benchmark::kMillisecond);

using CholSimplicial = Eigen::CholmodSimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;
BENCHMARK(factorise<CholSimplicial>)
    ->Name("cholmod_simplicial_llt")
    ->Arg(250)
    ->Arg(1000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond);
#endif

// Conjugate gradient warm-started from the exact solution perturbed by 1% (what a previous
// step's velocities give), to the relative tolerance 1e-10.
template <class Preconditioner>
void conjugate_gradient(benchmark::State& state) {
  const Problem& p = problem(static_cast<int>(state.range(0)));
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, Preconditioner>
      cg;
  cg.setTolerance(1e-10);
  cg.compute(p.full);
  LLT exact(p.lower);
  const Eigen::VectorXd x_exact = exact.solve(p.rhs);
  const Eigen::VectorXd guess =
      x_exact + 0.01 * x_exact.cwiseAbs().maxCoeff() * Eigen::VectorXd::Random(x_exact.size());
  Eigen::VectorXd x;
  for (auto _ : state) {
    cg.compute(p.full);
    x = cg.solveWithGuess(p.rhs, guess);
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["iterations"] = static_cast<double>(cg.iterations());
  state.counters["rel_residual"] = (p.full * x - p.rhs).norm() / p.rhs.norm();
}
BENCHMARK(conjugate_gradient<Eigen::DiagonalPreconditioner<double>>)
    ->Name("cg_jacobi_warm")
    ->Arg(250)
    ->Arg(1000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(conjugate_gradient<Eigen::IncompleteCholesky<double>>)
    ->Name("cg_ichol_warm")
    ->Arg(250)
    ->Arg(1000)
    ->Arg(4000)
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
