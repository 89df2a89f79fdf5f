#pragma once
// The scene registry (src/scene/registry.cpp): one row per scene. Light on purpose (no Eigen):
// the configuration schema reads the scene names and docs from it.
//
// A scene answers the engine's questions through its row: its geometry, where its measured
// window starts, whether it imposes a shear rate, its own configuration checks, its default
// frame spacing and cell, and the observers that measure it. Nothing outside a scene's file
// and this registry compares scene names or branches on which scene runs.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"

namespace sheardiff {

struct Scene;
class Observer;

// A problem a scene finds in a configuration: the key, and what is wrong with it and what is
// allowed (the parser adds where the configuration came from).
struct ConfigProblem {
  std::string key;
  std::string message;
};

// The cell a scene will build, in d, known before anything is placed (the parser checks the
// periodic edges against the neighbour cut-off with it).
struct PlannedCell {
  double lx = 0.0, ly = 0.0;
};

// One row of the registry: a scene is its file in src/scene (the builder and the functions
// below) plus this row.
struct SceneKind {
  const char* name;  // the value of scene.type
  const char* doc;   // its line in the configuration reference
  Scene (*build)(const Config& cfg);
  // The cell is periodic in y (Lees-Edwards) rather than bounded by walls.
  bool periodic_y;
  // The measured window starts at a detected steady state (and the run may stop
  // steady.measure_strain after it) rather than after run.transient_strain.
  bool measured_from_steady_state;
  // The flow imposes a shear rate J: the clock is the strain gammadot t, J is reported, and the
  // diffusion analysis is scaled by it. (The channel's clock is <u> t / a.)
  bool imposes_shear_rate = true;
  // The scene's own checks of a configuration, after every key is within its range: the first
  // problem, or none. Null: no checks of its own.
  std::optional<ConfigProblem> (*check)(const Config& cfg) = nullptr;
  // The trajectory's frame spacing, in the scene's clock, when output.frame_strain = 0. Null:
  // 0.035 J^1/4 strain (about 10 frames per persistence time over the seed's range of J).
  double (*default_frame_spacing)(const Config& cfg) = nullptr;
  // The cell, when the scene fixes it from its own keys. Null: the cell particles.N discs make
  // at particles.phi_init and particles.aspect (or particles.init_file's).
  PlannedCell (*planned_cell)(const Config& cfg) = nullptr;
  // The observers that measure the scene, in their update order (only those cfg asks for).
  std::vector<std::unique_ptr<Observer>> (*observers)(const Config& cfg,
                                                      const std::filesystem::path& out_dir);
};

// Every scene, in the order of the configuration reference.
const std::vector<SceneKind>& scene_registry();
// The row of scene.type = name; throws ConfigError for an unknown name.
const SceneKind& scene_kind(const std::string& name);

}  // namespace sheardiff
