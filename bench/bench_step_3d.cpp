// Where a step of spheres spends its time (issue 33): neighbour rebuild, pattern + symbolic
// analysis, assembly, numeric factorisation, back-substitution and the whole step, at N = 500,
// 1000 and 2000 spheres in the cell of configs/sweep_3d.toml at J = 1e-2 (scene.dimension = 3,
// aspect 1.5, ktilde = 1e4, contact.sliding_stiffness = "sideways", started at random at its
// volume fraction 0.52), after the packing has settled under the floating wall, with the
// settling's steps and strain, and the bulk volume fraction, as counters; and the process's
// peak resident memory. Also the observers' stress loops (stress_sample, stress_profiles).
//
// The settling is not what is timed, so it runs with a step ten times coarser (max_displacement
// and max_overlap_change 1e-2 d): until the gap changed by less than 0.5 % over the last strain,
// or 2 strains. The state then moves to a simulation with the sweep's own step, which runs
// 0.05 strain (the coarse step's overlaps relax) before anything is timed. At the sweep's step
// the settling of N = 2000 alone took about 2 CPU hours.
//
//   OMP_THREAD_LIMIT=1 build/bench/bench_step_3d --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <cmath>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "sheardiff/engine.hpp"
#include "sheardiff/integrator/integrators.hpp"
#include "sheardiff/integrator/stress.hpp"
#include "sheardiff/observe/pressure_cell.hpp"
#include "sheardiff/observe/profiles.hpp"

namespace {

using namespace sheardiff;

struct Prepared {
  std::unique_ptr<Simulation3> sim;
  Dynamics3* dynamics = nullptr;
  Config cfg;
  long settling_steps = 0;
  double settling_strain = 0.0;
  double last_dt() const { return sim->integrator().last_dt(); }
};

// The sweep's cell at J = 1e-2 for n spheres.
Config sweep_cell(int n) {
  Config c;
  c.scene.type = "pressure_shear";
  c.scene.dimension = 3;
  c.particles.n = n;
  c.particles.aspect = 1.5;
  c.particles.phi_init_spheres = 0.52;
  c.flow.j = 1e-2;
  c.contact.ktilde = 1e4;
  c.contact.sliding_stiffness = "sideways";
  return c;
}

// One settled cell per N, made once: the run's own simulation of spheres.
Prepared& prepared(int n) {
  static std::map<int, Prepared> cache;
  Prepared& p = cache[n];
  if (p.sim) return p;
  p.cfg = sweep_cell(n);
  Config coarse = p.cfg;
  coarse.integrator.max_displacement = 1e-2;
  coarse.integrator.max_overlap_change = 1e-2;
  Simulation3 settling(coarse);
  Dynamics3& s = settling.dynamics();
  // Settled: the gap changed by less than 0.5 % over the last strain, or the strain is spent.
  constexpr double max_settling_strain = 2.0;
  std::vector<std::pair<double, double>> gap;  // (strain, H) every 0.1 strain
  while (s.strain() < max_settling_strain) {
    settling.step();
    const double strain = s.strain();
    if (!gap.empty() && strain < gap.back().first + 0.1) continue;
    gap.emplace_back(strain, s.height());
    if (gap.size() > 10 &&
        std::abs(gap.back().second - gap[gap.size() - 11].second) < 0.005 * gap.back().second)
      break;
  }
  p.settling_steps = s.steps();
  p.settling_strain = s.strain();
  Archive out = Archive::writer();
  s.serialize(out);
  settling.serialize_integrator(out);
  p.sim = std::make_unique<Simulation3>(p.cfg);
  p.dynamics = &p.sim->dynamics();
  Archive in = Archive::reader(out.bytes());
  p.dynamics->serialize(in);
  p.sim->serialize_integrator(in);
  const double relaxed = p.dynamics->strain() + 0.05;
  while (p.dynamics->strain() < relaxed) p.sim->step();
  return p;
}

void label(benchmark::State& state, const Prepared& p) {
  const Dynamics3& d = *p.dynamics;
  const auto& rs = d.force_balance().system();
  state.counters["N"] = static_cast<double>(d.particles().n_mobile);
  state.counters["unknowns"] = static_cast<double>(rs.unknowns());
  state.counters["pairs"] = static_cast<double>(d.neighbours().pairs().size());
  state.counters["matrix_nnz"] = static_cast<double>(rs.matrix().nonZeros());
  state.counters["settling_steps"] = static_cast<double>(p.settling_steps);
  state.counters["settling_strain"] = p.settling_strain;
  // The process's peak resident memory: that of one N when run with a filter for one size.
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["peak_rss_MB"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
  // The bulk volume fraction, as the pressure cell measures it.
  state.counters["phi"] =
      PressureCellObserverOf<Dim3>::bulk_phi(d, p.cfg.observables.wall_exclusion);
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
                               p.last_dt(), d.wall_bodies());
    benchmark::ClobberMemory();
  }
  label(state, p);
}

const ResistanceSystem& assembled(Prepared& p) {
  Dynamics3& d = *p.dynamics;
  d.force_balance().assemble(d.particles(), d.box(), d.flow(), d.neighbours().pairs(), p.last_dt(),
                             d.wall_bodies());
  return d.force_balance().system();
}

void factorisation(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  const auto& a = assembled(p).matrix();
  auto llt = make_sparse_cholesky(p.cfg.solver.cholesky, 3);
  llt->analyze(a);
  for (auto _ : state) benchmark::DoNotOptimize(llt->factorize(a));
  label(state, p);
}

void back_substitution(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  const auto& rs = assembled(p);
  auto llt = make_sparse_cholesky(p.cfg.solver.cholesky, 3);
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
    if (!p.sim->try_step()) state.SkipWithError("solve failed");
  const double steps = static_cast<double>(d.steps() - steps0);
  state.counters["steps_per_strain"] = steps / (d.strain() - strain0);
  state.counters["rebuilds_per_step"] =
      static_cast<double>(d.neighbours().rebuilds() - rebuilds0) / steps;
  state.counters["factorisations_per_step"] =
      static_cast<double>(d.force_balance().system().factorisations() - fact0) / steps;
  label(state, p);
}

// The observers' pair-stress loops over the running cell's last solve: the cell's stress, which
// the pressure cell samples every step, and the gap profiles' binned stresses with their
// lubrication part (each pair's lubrication block formed again), every step of the measured
// window. Their difference is what the lubrication part costs.
void stress_sample(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  const auto& v = p.sim->integrator().velocities();
  for (auto _ : state) benchmark::DoNotOptimize(measure_stress(*p.dynamics, v, p.cfg.flow.lz));
  label(state, p);
}

void stress_profiles(benchmark::State& state) {
  Prepared& p = prepared(static_cast<int>(state.range(0)));
  const Dynamics3& d = *p.dynamics;
  const auto& v = p.sim->integrator().velocities();
  GapProfiles g(p.cfg.observables.profile_bin);
  g.add(d.particles(), v.u, 0.0, d.height(), band_section(d), 1.0);
  const auto stages = p.sim->integrator().stages(d);
  for (auto _ : state) {
    g.add_stress(d, stages, 0.0, p.cfg.flow.lz, 1.0);
    benchmark::ClobberMemory();
  }
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
BENCHMARK(stress_sample)->Apply(sizes);
BENCHMARK(stress_profiles)->Apply(sizes);

}  // namespace

// main: bench/main.cpp
