#pragma once
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/integrator/integrators.hpp"
#include "sheardiff/observe/stress.hpp"
#include "sheardiff/scene/scene.hpp"

namespace sheardiff {

// A run as a value: the scene, the engine composed for it and the integrator. Tests build one
// from a Config (or a hand-made Scene) and step it.
class Simulation {
 public:
  explicit Simulation(const Config& cfg);
  Simulation(const Config& cfg, Scene scene);

  // One integrator step; throws std::runtime_error if the linear solve fails.
  void step();
  // One integrator step; false if the linear solve failed (the state is then unchanged).
  bool try_step() { return integrator_->step(*dynamics_); }
  StressSample sample() const { return integrator_->sample(*dynamics_, cfg_.flow.lz); }

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

// Contact stability limit of explicit springs for these parameters (model.md section 7).
double explicit_stability_dt(const Config& cfg);

class Observer;
// The observers the scene and the config ask for (and only those), in their update order.
std::vector<std::unique_ptr<Observer>> make_observers(const Config& cfg,
                                                      const std::filesystem::path& out_dir);

// Whether the run needs the rotational unknowns (3 per particle) or only translation (2).
bool rotational_unknowns(const Config& cfg);

// The checks of a configuration that need the physics or input files (parse_config does the
// rest): a fixed dt of explicit springs below their stability limit, and particles.init_file
// readable with particles.N mobile particles. Throws ConfigError naming origin and the key.
// Writes nothing: `sheardiff check` and `run` call it before any output exists.
void validate_run_inputs(const Config& cfg, const std::string& origin);

// A run stopped by SIGINT/SIGTERM after writing its checkpoint.
struct RunInterrupted : std::runtime_error {
  RunInterrupted(int sig, const std::string& what) : std::runtime_error(what), signal(sig) {}
  int signal;
};

// Runs cfg to its end, writing trajectory.h5 (H5MD), config.toml, checkpoint.bin every
// output.checkpoint_strain, and at the end summary.json (whose presence marks a finished run;
// the checkpoint is then removed). resume = continue from out_dir/checkpoint.bin, cutting the
// trajectory back to the checkpoint's frames; the continuation is bit-identical to a run that
// was never stopped. Returns the summary.
nlohmann::json run_to_directory(const Config& cfg, const std::filesystem::path& out_dir,
                                bool progress, bool resume = false);

}  // namespace sheardiff
