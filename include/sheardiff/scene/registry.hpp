#pragma once
// The scene registry (src/scene/registry.cpp): one row per scene. Light on purpose (no Eigen):
// the configuration schema reads the scene names and docs from it.
#include <string>
#include <vector>

#include "sheardiff/config.hpp"

namespace sheardiff {

struct Scene;

// One row of the registry: a scene is its builder (one file in src/scene) plus this row.
// Nothing outside the registry compares scene names.
struct SceneKind {
  const char* name;  // the value of scene.type
  const char* doc;   // its line in the configuration reference
  Scene (*build)(const Config& cfg);
  // The cell is periodic in y (Lees-Edwards) rather than bounded by walls.
  bool periodic_y;
  // The run is measured from a detected steady state (and may stop steady.measure_strain after
  // it) rather than from run.transient_strain.
  bool measured_from_steady_state;
  // A pressure-driven channel between fixed walls: the clock is <u> t / a, the flow has no
  // shear rate J, and the channel's observer replaces the shear analyses.
  bool channel_flow = false;
};

// Every scene, in the order of the configuration reference.
const std::vector<SceneKind>& scene_registry();
// The row of scene.type = name; throws ConfigError for an unknown name.
const SceneKind& scene_kind(const std::string& name);

}  // namespace sheardiff
