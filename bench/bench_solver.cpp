// Solver choice for the per-step SPD system (issue "fast and accurate"): factorise the matrix of
// a dense sheared packing (simple shear, phi = 0.77, ktilde = 1e4, implicit springs) with each
// candidate. Prints time per factorisation + solve; the symbolic analysis is done once, as in a
// run between neighbour rebuilds.
//
//   build/bench/bench_solver --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <chrono>
#include <map>
#include <memory>

#ifdef SHEARDIFF_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include "sheardiff/run.hpp"
#include "sheardiff/solver/detail/cholmod_tuning.hpp"
#include "sheardiff/solver/sparse_cholesky.hpp"

namespace {

struct Problem {
  Eigen::SparseMatrix<double> lower;  // lower triangle, as assembled
  Eigen::SparseMatrix<double> full;
  Eigen::VectorXd rhs;
};

// The system a run of cfg assembles at its 30th step.
template <class Sim>
Problem assembled_after_30_steps(const sheardiff::Config& cfg) {
  Sim sim(cfg);
  for (int k = 0; k < 30; ++k) sim.step();
  Problem p;
  const auto& rs = sim.dynamics().force_balance().system();
  p.lower = rs.matrix();
  p.full = p.lower.selfadjointView<Eigen::Lower>();
  p.rhs = rs.rhs();
  return p;
}

const Problem& problem(int n) {
  static std::map<int, Problem> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  sheardiff::Config cfg;
  cfg.particles.n = n;
  cfg.particles.phi_init = 0.77;
  cfg.flow.j = 1e-2;
  cfg.contact.ktilde = 1e4;
  return cache.emplace(n, assembled_after_30_steps<sheardiff::Simulation>(cfg)).first->second;
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
using sheardiff::Supernodal;

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
// columns, each the slip mode of one contact (6 non-zeros), solved one by one or as one k-column
// block (as sheardiff does) on the tuned supernodal factor. Compare time per column with
// cholmod_supernodal_tuned's factorisation: that ratio bounds the budget of low_rank_pays
// (docs/performance.md, "Block columns for the sticking re-solve": a larger budget was measured
// not to pay in runs).
// k columns of nnz non-zeros each (a pair's slip mode) solved one by one or as one block on a
// factorised solver; the time per column as a counter.
template <bool Block, class Solver>
void time_columns(benchmark::State& state, const Solver& solver, Eigen::Index n, Eigen::Index k,
                  Eigen::Index nnz) {
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(n, k);
  for (Eigen::Index c = 0; c < k; ++c)
    for (Eigen::Index r = 0; r < nnz; ++r)
      w((c * 97 + r * (n / (nnz + 1))) % n, c) = 1.0 / (1.0 + r);
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

template <bool Block>
void cholmod_low_rank_columns(benchmark::State& state) {
  const Problem& p = problem(static_cast<int>(state.range(0)));
  Supernodal solver;
  sheardiff::tune_cholmod(solver.cholmod());
  solver.analyzePattern(p.lower);
  solver.factorize(p.lower);
  time_columns<Block>(state, solver, p.lower.rows(), state.range(1), 6);
}
BENCHMARK(cholmod_low_rank_columns<false>)
    ->Name("cholmod_columns_one_by_one")
    ->ArgsProduct({{1000, 4000}, {1, 8, 32, 64}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(cholmod_low_rank_columns<true>)
    ->Name("cholmod_columns_block")
    ->ArgsProduct({{1000, 4000}, {1, 8, 32, 64}})
    ->Unit(benchmark::kMillisecond);

// The matrix of spheres (scene.dimension = 3): the pressure cell of N spheres started at random at
// volume fraction 0.55 (the cell of configs/sweep_3d.toml, J = 1e-3), 30 steps, factorised with
// an ordering (0 AMD, 1 nested dissection, 2 METIS) and CHOLMOD's supernode relaxation (nrelax,
// zrelax) times relax / 10: whether the discs' tuning (tune_cholmod: nested dissection, relaxation
// doubled) holds for the spheres' larger separators (docs/performance.md, "Spheres").
const Problem& problem_spheres(int n) {
  static std::map<int, Problem> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  sheardiff::Config cfg;
  cfg.scene.type = "pressure_shear";
  cfg.scene.dimension = 3;
  cfg.particles.n = n;
  cfg.particles.aspect = 1.5;
  cfg.particles.phi_init_spheres = 0.55;
  cfg.flow.j = 1e-3;
  cfg.contact.ktilde = 1e4;
  return cache.emplace(n, assembled_after_30_steps<sheardiff::Simulation3>(cfg)).first->second;
}

void cholmod_spheres(benchmark::State& state) {
  const Problem& p = problem_spheres(static_cast<int>(state.range(0)));
  Supernodal solver;
  cholmod_common& c = solver.cholmod();
  c.nmethods = 1;
  constexpr int kOrdering[] = {CHOLMOD_AMD, CHOLMOD_NESDIS, CHOLMOD_METIS};
  c.method[0].ordering = kOrdering[state.range(1)];
  const double relax = static_cast<double>(state.range(2)) / 10.0;
  for (int k = 0; k < 3; ++k) {
    c.nrelax[k] = static_cast<std::size_t>(static_cast<double>(c.nrelax[k]) * relax);
    c.zrelax[k] *= relax;
  }
  time_factorise(state, p, solver);
  state.counters["nnz_L"] = c.lnz;
}
BENCHMARK(cholmod_spheres)
    ->ArgsProduct({{500, 1000, 2000}, {0, 1, 2}, {0, 2, 5, 10, 20}})
    ->Unit(benchmark::kMillisecond);

// Threads for the factorisation of spheres, whose supernodes are larger than the discs' (a dense
// front of hundreds of rows): the spheres' tuned factor of cholmod_spheres' matrix with OpenBLAS
// allowed range(1) threads, run under OMP_THREAD_LIMIT = 1 and 2 (which caps CHOLMOD's own
// OpenMP regions). Whether one run on two threads beats two runs side by side on one each
// (docs/performance.md "Threads").
void cholmod_spheres_threads(benchmark::State& state) {
  const Problem& p = problem_spheres(static_cast<int>(state.range(0)));
  Supernodal solver;
  sheardiff::tune_cholmod(solver.cholmod(), 3);
  sheardiff::set_blas_threads(static_cast<int>(state.range(1)));
  time_factorise(state, p, solver);
  sheardiff::set_blas_threads(1);
}
BENCHMARK(cholmod_spheres_threads)
    ->ArgsProduct({{1000, 2000}, {1, 2}})
    ->Unit(benchmark::kMillisecond);

// The Woodbury columns of spheres (12 non-zeros each: a pair's tangential rows), one by one
// and as one block, on the spheres' tuned factor of cholmod_spheres' matrix, with the back-solves
// a factorisation costs (solves_per_factorisation, as low_rank_pays reads it). At J = 1e-3 and
// N = 1000 a step switches ~170 contacts, two columns each: the re-solve pays on the old factor
// only if that many columns cost less than a factorisation (docs/performance.md "Spheres").
template <bool Block>
void cholmod_spheres_columns(benchmark::State& state) {
  const Problem& p = problem_spheres(static_cast<int>(state.range(0)));
  Supernodal solver;
  sheardiff::tune_cholmod(solver.cholmod(), 3);
  solver.analyzePattern(p.lower);
  solver.factorize(p.lower);
  time_columns<Block>(state, solver, p.lower.rows(), state.range(1), 12);
  auto ours = sheardiff::make_sparse_cholesky("cholmod", 3);
  ours->analyze(p.lower);
  state.counters["solves_per_factorisation"] = ours->solves_per_factorisation();
}
BENCHMARK(cholmod_spheres_columns<false>)
    ->Name("cholmod_spheres_columns_one_by_one")
    ->ArgsProduct({{1000}, {1, 32, 340}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(cholmod_spheres_columns<true>)
    ->Name("cholmod_spheres_columns_block")
    ->ArgsProduct({{1000}, {1, 32, 340}})
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

// A factorisation kept across steps (issue 13's route "keep a factorisation and iterate"):
// conjugate gradients on step k+1's system, preconditioned by the exact factor of step k's, in
// the pressure cell at J = 1e-4 (N = 1000; 30 or 3000 steps from the random packing, the second
// 0.08 strain into its compaction, then 20 step pairs; counters: cg_aged_factor below).
class PreviousFactor {
 public:
  void set(const sheardiff::SparseCholesky* f) { f_ = f; }
  template <class M>
  PreviousFactor& analyzePattern(const M&) {
    return *this;
  }
  template <class M>
  PreviousFactor& factorize(const M&) {
    return *this;
  }
  template <class M>
  PreviousFactor& compute(const M&) {
    return *this;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& r) const { return f_->solve(r); }
  Eigen::ComputationInfo info() const { return Eigen::Success; }

 private:
  const sheardiff::SparseCholesky* f_ = nullptr;
};

// Pairs of a factor of sim's system and the system `age` steps later, solved by conjugate
// gradients preconditioned by that factor to relative residuals of 1e-6 and 1e-10. Counters: the
// mean iterations, the back-solves one factorisation costs (CHOLMOD's flop counts; one iteration
// costs about one back-solve), and the measured ms of a factorisation, of its first back-solve and
// of the whole 1e-10 solve, in the same loop (a loaded machine slows them alike).
template <class Sim>
void cg_aged_factor(benchmark::State& state, Sim& sim, int dimension, int age) {
  const auto& rs = sim.dynamics().force_balance().system();
  double it6 = 0, it10 = 0, ratio = 0, t_fact = 0, t_solve = 0, t_cg = 0;
  using clock = std::chrono::steady_clock;
  auto ms = [](clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
  for (auto _ : state) {
    auto previous = sheardiff::make_sparse_cholesky("cholmod", dimension);
    previous->analyze(rs.matrix());
    const auto t0 = clock::now();
    previous->factorize(rs.matrix());
    const auto t1 = clock::now();
    Eigen::VectorXd y = previous->solve(rs.rhs());
    const auto t2 = clock::now();
    benchmark::DoNotOptimize(y.data());
    t_fact += ms(t1 - t0);
    t_solve += ms(t2 - t1);
    ratio = previous->solves_per_factorisation();
    for (int k = 0; k < age; ++k) sim.step();
    const Eigen::SparseMatrix<double> full = rs.matrix().template selfadjointView<Eigen::Lower>();
    for (double tol : {1e-6, 1e-10}) {
      Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                               PreviousFactor>
          cg;
      cg.preconditioner().set(previous.get());
      cg.setTolerance(tol);
      cg.compute(full);
      const auto t3 = clock::now();
      Eigen::VectorXd x = cg.solve(rs.rhs());
      if (tol < 1e-8) t_cg += ms(clock::now() - t3);
      benchmark::DoNotOptimize(x.data());
      (tol > 1e-8 ? it6 : it10) += static_cast<double>(cg.iterations());
    }
  }
  const auto pairs = static_cast<double>(state.iterations());
  state.counters["iterations_1e-6"] = it6 / pairs;
  state.counters["iterations_1e-10"] = it10 / pairs;
  state.counters["cg_1e-10_ms"] = t_cg / pairs;
  state.counters["solves_per_factorisation"] = ratio;
  state.counters["factorise_ms"] = t_fact / pairs;
  state.counters["back_solve_ms"] = t_solve / pairs;
}

void cg_previous_step_factor(benchmark::State& state) {
  sheardiff::Config cfg;
  cfg.scene.type = "pressure_shear";
  cfg.particles.n = static_cast<int>(state.range(0));
  cfg.particles.phi_init = 0.75;
  cfg.flow.j = 1e-4;
  sheardiff::Simulation sim(cfg);
  for (int k = 0; k < state.range(1); ++k) sim.step();
  cg_aged_factor(state, sim, 2, 1);
}
// The same route for spheres, whose factorisation costs more back-solves than the discs' (a step
// is ~80 % factorisation at N = 1000): the pressure cell of configs/sweep_3d.toml (1000 spheres,
// aspect 1.5, sliding_stiffness = "sideways") at J = 5e-2 (range(1) = 0, started at 0.48) or 1e-3
// (range(1) = 1, started at 0.55), 300 steps from the random start, then pairs of a factor and
// the system range(2) steps later. The kept factor pays if the conjugate gradients take less
// than a factorisation.
void cg_aged_factor_spheres(benchmark::State& state) {
  sheardiff::Config cfg;
  cfg.scene.type = "pressure_shear";
  cfg.scene.dimension = 3;
  cfg.particles.n = static_cast<int>(state.range(0));
  cfg.particles.aspect = 1.5;
  cfg.contact.ktilde = 1e4;
  cfg.contact.sliding_stiffness = "sideways";
  cfg.flow.j = state.range(1) == 0 ? 5e-2 : 1e-3;
  cfg.particles.phi_init_spheres = state.range(1) == 0 ? 0.48 : 0.55;
  sheardiff::Simulation3 sim(cfg);
  for (int k = 0; k < 300; ++k) sim.step();
  cg_aged_factor(state, sim, 3, static_cast<int>(state.range(2)));
}

#ifdef SHEARDIFF_HAVE_CHOLMOD
BENCHMARK(cg_previous_step_factor)
    ->Args({1000, 30})
    ->Args({1000, 3000})
    ->Iterations(20)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(cg_aged_factor_spheres)
    ->ArgsProduct({{1000}, {0, 1}, {1, 3, 10}})
    ->Iterations(10)
    ->Unit(benchmark::kMillisecond);
#endif

}  // namespace

// main: bench/main.cpp
