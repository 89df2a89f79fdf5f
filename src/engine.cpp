// The engine composed for a configuration: the scene, the pair laws, the force balance and the
// integrator, and the checks of a configuration that need them.
#include "sheardiff/engine.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "sheardiff/interactions/fluid_layer.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/scene/registry.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {

double interaction_range_factor(const Config& cfg) {
  return PairLaws::from(cfg).range_factor();
}

double explicit_stability_dt(const Config& cfg) {
  return PairLaws::from(cfg).explicit_stability_dt(cfg.scene.dimension);
}

bool rotational_unknowns(const Config& cfg) {
  // Without a law that couples rotation to translation, omega = omega_inf + T_ext / drag.
  return cfg.solver.rotations == "always" || PairLaws::from(cfg).needs_rotations();
}

void validate_run_inputs(const Config& cfg, const std::string& origin) {
  if (cfg.integrator.type != IntegratorType::Implicit && cfg.integrator.dt > 0.0) {
    const double limit = explicit_stability_dt(cfg);
    if (cfg.integrator.dt >= limit)
      throw ConfigError(fmt::format(
          "{}: integrator.dt: fixed dt = {} is not below the stability limit 2 R/k = {:.3g} "
          "eta/P of explicit springs (smallest particles in their densest packing, normal and "
          "slip modes, "
          "docs/model.md section 7; integrator.type = \"{}\", contact.ktilde = {}); use "
          "integrator.dt < "
          "{:.3g}, integrator.dt = 0 (adaptive), or "
          "integrator.type = \"implicit\"",
          origin, cfg.integrator.dt, limit, to_string(cfg.integrator.type), cfg.contact.ktilde,
          limit));
  }
  double lx = 0.0, ly = 0.0, amax = 0.5 * std::max(1.0, cfg.particles.size_ratio);
  if (!cfg.particles.init_file.empty()) {
    try {
      const Packing pk = initial_packing(cfg, scene_kind(cfg.scene.type).periodic_y);
      lx = pk.lx, ly = pk.ly;
      for (double a : pk.radius) amax = std::max(amax, a);
    } catch (const ConfigError& e) {
      throw ConfigError(fmt::format("{}: {}", origin, e.what()));
    } catch (const std::exception& e) {
      throw ConfigError(fmt::format("{}: particles.init_file: {}", origin, e.what()));
    }
  } else if (cfg.scene.dimension == 3 && scene_kind(cfg.scene.type).planned_cell_3d) {
    // Periodic in x and z: the narrower edge counts.
    const PlannedCell cell = scene_kind(cfg.scene.type).planned_cell_3d(cfg);
    lx = std::min(cell.lx, cell.lz), ly = cell.ly;
  } else if (const auto planned = scene_kind(cfg.scene.type).planned_cell) {
    const PlannedCell cell = planned(cfg);
    lx = cell.lx, ly = cell.ly;
  } else {
    // The cell random_packing makes, without placing anything.
    double area = 0.0;
    for (int s : bidisperse_species(cfg.particles.n, cfg.particles.mix, cfg.particles.size_ratio)) {
      const double a = s == 0 ? 0.5 : 0.5 * cfg.particles.size_ratio;
      area += kPi * a * a;
    }
    lx = std::sqrt(area / cfg.particles.phi_init / cfg.particles.aspect);
    ly = cfg.particles.aspect * lx;
  }
  // The neighbour list holds one image of each pair: a periodic edge within two list cut-offs
  // of the largest pair lets a disc meet its own image (ignored, so its stress is lost) or a
  // pair meet twice (one contact history for two images).
  const double cutoff = 2.0 * amax * interaction_range_factor(cfg) + cfg.neighbour.skin;
  const bool periodic_y = scene_kind(cfg.scene.type).periodic_y;
  const double edge = periodic_y ? std::min(lx, ly) : lx;
  if (!(edge > 2.0 * cutoff))
    throw ConfigError(fmt::format(
        "{}: particles.N: the periodic cell is {:.3g} x {:.3g} d ({} = {:.3g} d), but a periodic "
        "edge must exceed twice the neighbour cut-off of the largest pair, 2 x {:.3g} = {:.3g} d "
        "(diameter {:g} d, lubrication range and neighbour.skin = {:g} d), or a disc meets its "
        "own image; raise particles.N{}, lower neighbour.skin or lubrication.h_max",
        origin, lx, ly, periodic_y && ly < lx ? "Ly" : "Lx", edge, cutoff, 2.0 * cutoff, 2.0 * amax,
        cfg.neighbour.skin,
        cfg.particles.init_file.empty() ? ", bring particles.aspect closer to 1" : ""));
}

StepLimits step_limits(const Config& cfg, double clock_rate, bool implicit_springs) {
  StepLimits lim;
  lim.fixed_dt = cfg.integrator.dt;
  lim.max_displacement = cfg.integrator.max_displacement;
  lim.max_gap_fraction = cfg.integrator.max_gap_fraction;
  lim.max_overlap_change = overlap_change_limit(cfg);
  lim.max_entry_overlap = cfg.integrator.max_entry_overlap;
  lim.max_strain_step = cfg.integrator.max_strain_step;
  lim.end_time = cfg.run.strain / clock_rate;
  if (!implicit_springs)
    lim.explicit_dt = cfg.integrator.explicit_safety * explicit_stability_dt(cfg);
  return lim;
}

template <>
Scene build_scene_of<Dim2>(const Config& cfg) {
  return build_scene(cfg);
}

template <>
Scene3 build_scene_of<Dim3>(const Config& cfg) {
  const auto build = scene_kind(cfg.scene.type).build_3d;
  if (build == nullptr)
    throw ConfigError(fmt::format(
        "scene.dimension: scene.type = \"{}\" has no scene of spheres; scene.dimension = 3 is "
        "allowed for {}",
        cfg.scene.type, scenes_of_spheres()));
  return build(cfg);
}

template <class D>
SimulationOf<D>::SimulationOf(const Config& cfg) : SimulationOf(cfg, build_scene_of<D>(cfg)) {}

template <class D>
SimulationOf<D>::SimulationOf(const Config& cfg, SceneOf<D> scene)
    : cfg_(cfg), integrator_(make_integrator_of<D>(cfg.integrator.type)) {
  const StepLimits lim = step_limits(cfg, scene.flow.clock_rate(), integrator_->implicit_springs());
  const double range = interaction_range_factor(cfg);
  const bool rotations = rotational_unknowns(cfg);
  ForceBalanceOf<D> fb(PairLaws::from(cfg), rotations ? D::body : D::space,
                       integrator_->implicit_springs(), cfg.solver.cholesky);
  if constexpr (D::space == 2) {
    if (const auto& g = scene.fluid)
      fb.set_fluid(FluidLayer(g->y_lo, g->y_hi, g->cells, g->lx, g->lz, g->reach));
  }
  dynamics_ = std::make_unique<Dynamics>(
      std::move(scene.particles), scene.box, scene.flow, std::move(fb),
      NeighbourListOf<D>(range, cfg.neighbour.skin), lim, std::move(scene.walls));
}

template <class D>
void SimulationOf<D>::step() {
  if (!integrator_->step(*dynamics_))
    throw std::runtime_error(fmt::format(
        "linear solve failed at step {} (strain {:.6g}): the resistance matrix is not positive "
        "definite or the velocities are not finite",
        dynamics_->steps(), dynamics_->strain()));
}

template class SimulationOf<Dim2>;
template class SimulationOf<Dim3>;

}  // namespace sheardiff
