// Where a step's time goes (issue 5): neighbour rebuild, pattern + symbolic analysis, assembly
// (pair laws and matrix), numeric factorisation, back-substitution and the whole step, at
// N = 250, 1000, 4000, on a sheared dense packing (simple shear, phi = 0.77, J = 1e-2,
// ktilde = 1e4, implicit springs, 30 steps after the random packing), plus the variants whose
// savings the issue asks to measure (frictionless with 2 or 3 unknowns per particle, no
// lubrication with explicit springs, the pressure cell).
//
//   OMP_THREAD_LIMIT=1 build/bench/bench_step --benchmark_counters_tabular=true
//   OMP_THREAD_LIMIT=1 build/bench/bench_step --benchmark_format=json > step.json &&
//     /usr/bin/python3 tools/cost_exponent.py step.json
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <utility>

#include "sheardiff/run.hpp"

namespace {

using sheardiff::Config;
using sheardiff::Simulation;

enum Variant : int {
  kFrictional = 0,     // the default engine: mu = 0.5, 3 unknowns per particle
  kFrictionless2 = 1,  // mu = 0, tangential lubrication off: 2 unknowns per particle
  kFrictionless3 = 2,  // the same physics keeping the rotational unknowns
  kNoLubrication = 3,  // no lubrication, explicit Euler springs: diagonal system
  kPressureCell = 4,   // pressure_shear, floating wall (bordered system)
};
constexpr const char* kVariantNames[] = {"frictional", "frictionless_2dof", "frictionless_3dof",
                                         "no_lubrication_euler", "pressure_cell"};

Config config_of(int n, int variant) {
  Config cfg;
  cfg.particles.n = n;
  cfg.particles.phi_init = 0.77;
  cfg.flow.j = 1e-2;
  cfg.contact.ktilde = 1e4;
  switch (variant) {
    case kFrictionless2:
    case kFrictionless3:
      cfg.contact.mu = 0.0;
      cfg.lubrication.tangential = false;
      if (variant == kFrictionless3) cfg.solver.rotations = "always";
      break;
    case kNoLubrication:
      cfg.lubrication.enabled = false;
      cfg.integrator.type = sheardiff::IntegratorType::Euler;
      break;
    case kPressureCell:
      cfg.scene.type = "pressure_shear";
      cfg.particles.phi_init = 0.75;
      break;
    default:
      break;
  }
  return cfg;
}

// One prepared run per (N, variant), made once: 30 steps past the random packing.
Simulation& prepared(int n, int variant) {
  static std::map<std::pair<int, int>, std::unique_ptr<Simulation>> cache;
  auto& slot = cache[{n, variant}];
  if (!slot) {
    slot = std::make_unique<Simulation>(config_of(n, variant));
    for (int k = 0; k < 30; ++k) slot->step();
  }
  return *slot;
}

void label(benchmark::State& state, Simulation& sim) {
  const auto& rs = sim.dynamics().force_balance().system();
  state.counters["N"] = static_cast<double>(sim.dynamics().particles().n_mobile);
  state.counters["unknowns"] = static_cast<double>(rs.unknowns());
  state.counters["pairs"] = static_cast<double>(sim.dynamics().neighbours().pairs().size());
  state.SetLabel(kVariantNames[state.range(1)]);
}

double implicit_dt(const Simulation& sim) {
  return sim.integrator().implicit_springs() ? sim.integrator().last_dt() : 0.0;
}

void neighbour_rebuild(benchmark::State& state) {
  Simulation& sim = prepared(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  sheardiff::Particles p = sim.dynamics().particles();
  sheardiff::NeighbourList list = sim.dynamics().neighbours();
  for (auto _ : state) {
    list.rebuild(p, sim.dynamics().box());
    benchmark::DoNotOptimize(list.pairs().data());
  }
  label(state, sim);
}

// New sparsity pattern, value offsets and the symbolic analysis: paid once per rebuild.
void pattern_and_analysis(benchmark::State& state) {
  Simulation& sim = prepared(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  auto& d = sim.dynamics();
  for (auto _ : state) d.force_balance().on_rebuild(d.particles(), d.neighbours().pairs());
  label(state, sim);
}

void assembly(benchmark::State& state) {
  Simulation& sim = prepared(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  auto& d = sim.dynamics();
  d.force_balance().on_rebuild(d.particles(), d.neighbours().pairs());
  const double dt = implicit_dt(sim);
  for (auto _ : state) {
    d.force_balance().assemble(d.particles(), d.box(), d.flow(), d.neighbours().pairs(), dt,
                               d.wall_bodies());
    benchmark::ClobberMemory();
  }
  label(state, sim);
}

// The step's system assembled at the scene's implicit dt, as the factorisation sees it.
const sheardiff::ResistanceSystem& assembled(Simulation& sim) {
  auto& d = sim.dynamics();
  d.force_balance().assemble(d.particles(), d.box(), d.flow(), d.neighbours().pairs(),
                             implicit_dt(sim), d.wall_bodies());
  return d.force_balance().system();
}

// Numeric factorisation alone (symbolic analysis reused), then the back-substitution alone.
void factorisation(benchmark::State& state) {
  Simulation& sim = prepared(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const auto& a = assembled(sim).matrix();
  auto llt = sheardiff::make_sparse_cholesky(sim.config().solver.cholesky);
  llt->analyze(a);
  for (auto _ : state) benchmark::DoNotOptimize(llt->factorize(a));
  label(state, sim);
}

void back_substitution(benchmark::State& state) {
  Simulation& sim = prepared(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const auto& rs = assembled(sim);
  auto llt = sheardiff::make_sparse_cholesky(sim.config().solver.cholesky);
  llt->analyze(rs.matrix());
  llt->factorize(rs.matrix());
  for (auto _ : state) {
    Eigen::VectorXd x = llt->solve(rs.rhs());
    benchmark::DoNotOptimize(x.data());
  }
  label(state, sim);
}

// Whole steps of the running simulation (rebuilds included when they fall due).
void full_step(benchmark::State& state) {
  Simulation& sim = prepared(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const long steps0 = sim.dynamics().steps();
  const auto rebuilds0 = sim.dynamics().neighbours().rebuilds();
  const auto fact0 = sim.dynamics().force_balance().system().factorisations();
  const auto terms0 = sim.dynamics().force_balance().system().low_rank_terms();
  for (auto _ : state) sim.step();
  const double steps = static_cast<double>(sim.dynamics().steps() - steps0);
  state.counters["rebuilds_per_step"] =
      static_cast<double>(sim.dynamics().neighbours().rebuilds() - rebuilds0) / steps;
  state.counters["factorisations_per_step"] =
      static_cast<double>(sim.dynamics().force_balance().system().factorisations() - fact0) / steps;
  // Contacts switched to sticking and solved as low-rank terms on the step's factor.
  state.counters["low_rank_terms_per_step"] =
      static_cast<double>(sim.dynamics().force_balance().system().low_rank_terms() - terms0) /
      steps;
  label(state, sim);
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int n : {250, 1000, 4000}) b->Args({n, kFrictional});
  b->Unit(benchmark::kMillisecond);
}
void variants(benchmark::internal::Benchmark* b) {
  for (int n : {250, 1000, 4000}) b->Args({n, kFrictional});
  for (int v : {kFrictionless2, kFrictionless3, kNoLubrication, kPressureCell}) b->Args({1000, v});
  b->Unit(benchmark::kMillisecond);
}

BENCHMARK(neighbour_rebuild)->Apply(sizes);
BENCHMARK(pattern_and_analysis)->Apply(sizes);
BENCHMARK(assembly)->Apply(variants);
BENCHMARK(factorisation)->Apply(sizes)->Args({1000, kFrictionless2})->Args({1000, kFrictionless3});
BENCHMARK(back_substitution)->Apply(sizes);
BENCHMARK(full_step)->Apply(variants);

}  // namespace

// main: bench/main.cpp
