// Where a step of spheres spends its time (issue 33): neighbour rebuild, pattern + symbolic
// analysis, assembly, numeric factorisation, back-substitution and the whole step, at N = 500,
// 1000 and 2000 spheres in the pressure cell of spheres (scene/pressure_shear_3d.cpp; J = 1e-2,
// ktilde = 1e4, implicit springs, 6 unknowns per sphere), measured after the packing has
// compacted under the floating wall (the wall held by the packing for 500 consecutive steps),
// with the compaction's steps and strain, and the factor's fill, as counters.
//
//   OMP_THREAD_LIMIT=1 build/bench/bench_step_3d --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "sheardiff/engine.hpp"
#include "sheardiff/integrator/integrators.hpp"
#include "sheardiff/scene/scene.hpp"

namespace {

using namespace sheardiff;

struct Prepared {
  std::unique_ptr<Dynamics3> dynamics;
  std::unique_ptr<IntegratorOf<Dim3>> integrator;
  Config cfg;
  long compaction_steps = 0;
  double compaction_strain = 0.0;
};

// One compacted cell per N, made once.
Prepared& prepared(int n) {
  static std::map<int, Prepared> cache;
  Prepared& p = cache[n];
  if (p.dynamics) return p;
  p.cfg.particles.n = n;
  p.cfg.flow.j = 1e-2;
  p.cfg.contact.ktilde = 1e4;
  Scene3 sc = build_pressure_shear_3d(p.cfg);
  ForceBalance3 fb(PairLaws::from(p.cfg), rotational_unknowns(p.cfg) ? 6 : 3, true,
                   p.cfg.solver.cholesky);
  p.dynamics = std::make_unique<Dynamics3>(
      std::move(sc.particles), sc.box, sc.flow, std::move(fb),
      NeighbourList3(interaction_range_factor(p.cfg), p.cfg.neighbour.skin),
      step_limits(p.cfg, sc.flow.clock_rate(), true), std::move(sc.walls));
  p.integrator = make_integrator_of<Dim3>(IntegratorType::Implicit);
  int held = 0;
  while (held < 500 && p.dynamics->steps() < 200000) {
    if (!p.integrator->step(*p.dynamics)) throw std::runtime_error("solve failed");
    held = p.integrator->velocities().wall_free_fall ? 0 : held + 1;
  }
  p.compaction_steps = p.dynamics->steps();
  p.compaction_strain = p.dynamics->strain();
  return p;
}

void label(benchmark::State& state, const Prepared& p) {
  const Dynamics3& d = *p.dynamics;
  const auto& rs = d.force_balance().system();
  state.counters["N"] = static_cast<double>(d.particles().n_mobile);
  state.counters["unknowns"] = static_cast<double>(rs.unknowns());
  state.counters["pairs"] = static_cast<double>(d.neighbours().pairs().size());
  state.counters["matrix_nnz"] = static_cast<double>(rs.matrix().nonZeros());
  state.counters["compaction_steps"] = static_cast<double>(p.compaction_steps);
  state.counters["compaction_strain"] = p.compaction_strain;
  // Volume fraction between the walls' centre planes (the walls' own half spheres excluded).
  double volume = 0.0;
  for (std::size_t i = 0; i < d.particles().n_mobile; ++i) {
    const double a = d.particles().radius[i];
    volume += 4.0 / 3.0 * kPi * a * a * a;
  }
  state.counters["phi"] = volume / (d.box().lx * d.box().lz * d.height());
}

void neighbour_rebuild(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  Particles3 particles = p.dynamics->particles();
  NeighbourList3 list = p.dynamics->neighbours();
  for (auto _ : state) {
    list.rebuild(particles, p.dynamics->box());
    benchmark::DoNotOptimize(list.pairs().data());
  }
  label(state, p);
}

void pattern_and_analysis(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  Dynamics3& d = *p.dynamics;
  for (auto _ : state) d.force_balance().on_rebuild(d.particles(), d.neighbours().pairs());
  label(state, p);
}

void assembly(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  Dynamics3& d = *p.dynamics;
  d.force_balance().on_rebuild(d.particles(), d.neighbours().pairs());
  for (auto _ : state) {
    d.force_balance().assemble(d.particles(), d.box(), d.flow(), d.neighbours().pairs(),
                               p.integrator->last_dt(), d.wall_bodies());
    benchmark::ClobberMemory();
  }
  label(state, p);
}

const ResistanceSystem& assembled(Prepared& p) {
  Dynamics3& d = *p.dynamics;
  d.force_balance().assemble(d.particles(), d.box(), d.flow(), d.neighbours().pairs(),
                             p.integrator->last_dt(), d.wall_bodies());
  return d.force_balance().system();
}

void factorisation(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  const auto& a = assembled(p).matrix();
  auto llt = make_sparse_cholesky(p.cfg.solver.cholesky);
  llt->analyze(a);
  for (auto _ : state) benchmark::DoNotOptimize(llt->factorize(a));
  label(state, p);
}

void back_substitution(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  const auto& rs = assembled(p);
  auto llt = make_sparse_cholesky(p.cfg.solver.cholesky);
  llt->analyze(rs.matrix());
  llt->factorize(rs.matrix());
  for (auto _ : state) {
    Eigen::VectorXd x = llt->solve(rs.rhs());
    benchmark::DoNotOptimize(x.data());
  }
  label(state, p);
}

// Whole steps of the running cell (rebuilds included when they fall due).
void full_step(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  Dynamics3& d = *p.dynamics;
  const long steps0 = d.steps();
  const double strain0 = d.strain();
  const auto rebuilds0 = d.neighbours().rebuilds();
  const auto fact0 = d.force_balance().system().factorisations();
  for (auto _ : state)
    if (!p.integrator->step(d)) state.SkipWithError("solve failed");
  const double steps = static_cast<double>(d.steps() - steps0);
  state.counters["steps_per_strain"] = steps / (d.strain() - strain0);
  state.counters["rebuilds_per_step"] =
      static_cast<double>(d.neighbours().rebuilds() - rebuilds0) / steps;
  state.counters["factorisations_per_step"] =
      static_cast<double>(d.force_balance().system().factorisations() - fact0) / steps;
  label(state, p);
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int n : {500, 1000, 2000}) b->Args({n});
  b->Unit(benchmark::kMillisecond);
}

BENCHMARK(neighbour_rebuild)->Apply(sizes);
BENCHMARK(pattern_and_analysis)->Apply(sizes);
BENCHMARK(assembly)->Apply(sizes);
BENCHMARK(factorisation)->Apply(sizes);
BENCHMARK(back_substitution)->Apply(sizes);
BENCHMARK(full_step)->Apply(sizes);

}  // namespace

BENCHMARK_MAIN();
