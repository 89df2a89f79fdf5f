#pragma once
// The engine as a value: constructed from a configuration (or a hand-made scene), stepped, its
// state read. Nothing here writes a file: a run to a directory is run.hpp.
#include <memory>
#include <string>
#include <type_traits>

#include "sheardiff/config.hpp"
#include "sheardiff/integrator/integrators.hpp"
#include "sheardiff/integrator/stress.hpp"
#include "sheardiff/scene/scene.hpp"

namespace sheardiff {

// The scene of a dimension: discs (Scene) or spheres (Scene3).
template <class D>
using SceneOf = std::conditional_t<D::space == 2, Scene, Scene3>;

// The scene cfg asks for in dimension D (scene.dimension), built.
template <class D>
SceneOf<D> build_scene_of(const Config& cfg);

// A run as a value: the scene, the engine composed for it and the integrator, in the dimension
// D. Tests build one from a Config (or a hand-made scene) and step it.
template <class D>
class SimulationOf {
 public:
  using Dynamics = DynamicsOf<D>;
  using Integrator = IntegratorOf<D>;

  explicit SimulationOf(const Config& cfg);
  SimulationOf(const Config& cfg, SceneOf<D> scene);

  // One integrator step; throws std::runtime_error if the linear solve fails.
  void step();
  // One integrator step; false if the linear solve failed (the state is then unchanged).
  bool try_step() { return integrator_->step(*dynamics_); }
  StressSample sample() const { return integrator_->sample(*dynamics_, cfg_.flow.lz); }
  // Velocities and stresses at the configuration as it is before the first step (the frame at
  // step 0); false if the solve failed. Integrator::solve_at_rest.
  bool solve_at_rest() { return integrator_->solve_at_rest(*dynamics_); }
  StressSample sample_at_rest() const {
    return measure_stress(*dynamics_, integrator_->velocities(), cfg_.flow.lz);
  }

  const Config& config() const { return cfg_; }
  Dynamics& dynamics() { return *dynamics_; }
  const Dynamics& dynamics() const { return *dynamics_; }
  const Integrator& integrator() const { return *integrator_; }
  void serialize_integrator(Archive& a) { integrator_->serialize(a); }

 private:
  Config cfg_;
  std::unique_ptr<Integrator> integrator_;
  std::unique_ptr<Dynamics> dynamics_;
};

using Simulation = SimulationOf<Dim2>;
using Simulation3 = SimulationOf<Dim3>;

// Pair interaction range over the sum of the radii: lubrication reaches gaps up to h_max.
double interaction_range_factor(const Config& cfg);

// Contact stability limit of explicit springs for these parameters (docs/model.md section 7).
double explicit_stability_dt(const Config& cfg);

// Whether the run needs the rotational unknowns (3 per disc, 6 per sphere) or only translation.
bool rotational_unknowns(const Config& cfg);

// The limits on one step a configuration sets (docs/model.md section 7), for a flow whose clock
// runs at clock_rate and an integrator with (implicit_springs) or without implicit springs.
StepLimits step_limits(const Config& cfg, double clock_rate, bool implicit_springs);

// The checks of a configuration that need the physics or input files (parse_config does the
// rest): a fixed dt of explicit springs below their stability limit, particles.init_file
// readable with particles.N mobile particles, and a periodic cell wider than two neighbour
// cut-offs of the largest pair. Throws ConfigError naming origin and the key.
// Writes nothing: `sheardiff check` and `run` call it before any output exists.
void validate_run_inputs(const Config& cfg, const std::string& origin);

}  // namespace sheardiff
