#pragma once
// The scene registry (src/scene/registry.cpp): one row per scene. Light on purpose (no Eigen):
// the configuration schema reads the scene names and docs from it.
//
// A scene answers the run's questions through its row: its geometry, what it measures (and so
// where its measured window starts and whether it imposes a shear rate), its own configuration
// checks, its default frame spacing and cell. Nothing outside a scene's file and this registry
// compares scene names.
#include <optional>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"

namespace sheardiff {

struct Scene;
struct Scene3;

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
  double lz = 0.0;  // spheres (scene.dimension = 3); 0 for discs
};

// What a scene measures; the run composes the observers for it (run_parts.cpp, make_observers).
enum class Measures {
  // Rheology and the shear analyses (profiles between walls, diffusion) after
  // run.transient_strain.
  ShearAfterTransient,
  // The same from the steady state the pressure cell's test detects (the run may stop
  // steady.measure_strain after it).
  ShearFromSteadyState,
  // The channel's migration: its profiles and time series, in the clock <u> t / a.
  ChannelMigration,
};

// One row of the registry: a scene is its file in src/scene (the builder and the optional
// functions below) plus this row.
struct SceneKind {
  const char* name;  // the value of scene.type
  const char* doc;   // its line in the configuration reference
  Scene (*build)(const Config& cfg);
  // The cell is periodic in y (Lees-Edwards) rather than bounded by walls.
  bool periodic_y;
  Measures measures;
  // The scene's own checks of a configuration, after every key is within its range: the first
  // problem, or none. Null: no checks of its own.
  std::optional<ConfigProblem> (*check)(const Config& cfg) = nullptr;
  // The trajectory's frame spacing, in the scene's clock, when output.frame_strain = 0. Null:
  // 0.035 J^1/4 strain (about 10 frames per persistence time over the seed's range of J).
  double (*default_frame_spacing)(const Config& cfg) = nullptr;
  // The cell, when the scene fixes it from its own keys. Null: the cell particles.N discs make
  // at particles.phi_init and particles.aspect (or particles.init_file's).
  PlannedCell (*planned_cell)(const Config& cfg) = nullptr;
  // The scene has a scene of spheres (scene.dimension = 3): its builder and its cell.
  bool spheres = false;
  Scene3 (*build_3d)(const Config& cfg) = nullptr;
  PlannedCell (*planned_cell_3d)(const Config& cfg) = nullptr;

  // The measured window starts at a detected steady state, not after run.transient_strain.
  bool measured_from_steady_state() const { return measures == Measures::ShearFromSteadyState; }
  // The flow imposes a shear rate J: the clock is the strain gammadot t, J is reported, and the
  // diffusion analysis is scaled by it.
  bool imposes_shear_rate() const { return measures != Measures::ChannelMigration; }
};

// Every scene, in the order of the configuration reference.
const std::vector<SceneKind>& scene_registry();
// The row of scene.type = name; throws ConfigError for an unknown name.
const SceneKind& scene_kind(const std::string& name);
// The scenes that have a scene of spheres, as text for an error ("`pressure_shear`").
std::string scenes_of_spheres();

}  // namespace sheardiff
