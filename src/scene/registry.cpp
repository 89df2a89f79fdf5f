// The scene registry: one row per scene. A new scene is its file src/scene/NAME.cpp (the
// builder and the scene's answers) plus one row here (and the declarations above it).
//
// The config parser's fuzz target (tests/fuzz) compiles this file alone for the scene names, with
// SHEARDIFF_SCENE_NAMES_ONLY: then none of the scenes' functions is linked.
#include "sheardiff/scene/registry.hpp"

#include <fmt/format.h>

#ifndef SHEARDIFF_SCENE_NAMES_ONLY
#include "sheardiff/scene/scene.hpp"
#define SHEARDIFF_SCENE(f) f
#else
#define SHEARDIFF_SCENE(f) nullptr
#endif

namespace sheardiff {

// Each scene's functions, one file each in src/scene.
Scene build_simple_shear(const Config& cfg);
Scene build_pressure_shear(const Config& cfg);
Scene build_channel(const Config& cfg);
std::optional<ConfigProblem> check_channel(const Config& cfg);
double channel_frame_spacing(const Config& cfg);
PlannedCell channel_cell(const Config& cfg);
PlannedCell pressure_shear_3d_cell(const Config& cfg);
Scene3 build_simple_shear_3d(const Config& cfg);
PlannedCell simple_shear_3d_cell(const Config& cfg);

const std::vector<SceneKind>& scene_registry() {
  static const std::vector<SceneKind> rows = {
      {.name = "simple_shear",
       .doc =
           "`simple_shear` = Lees-Edwards periodic cell at fixed area (discs) or volume (spheres) "
           "fraction and shear rate",
       .build = SHEARDIFF_SCENE(build_simple_shear),
       .periodic_y = true,
       .measures = Measures::ShearAfterTransient,
       .spheres = true,
       .build_3d = SHEARDIFF_SCENE(build_simple_shear_3d),
       .planned_cell_3d = SHEARDIFF_SCENE(simple_shear_3d_cell)},
      {.name = "pressure_shear",
       .doc = "`pressure_shear` = plane shear between rough walls, the top wall floating under "
              "the load P Lx lz (the packing dilates to phi(J))",
       .build = SHEARDIFF_SCENE(build_pressure_shear),
       .periodic_y = false,
       .measures = Measures::ShearFromSteadyState,
       .spheres = true,
       .build_3d = SHEARDIFF_SCENE(build_pressure_shear_3d),
       .planned_cell_3d = SHEARDIFF_SCENE(pressure_shear_3d_cell)},
      {.name = "channel",
       .doc = "`channel` = pressure-driven flow of monodisperse discs between two fixed rows of "
              "wall discs at a fixed mean velocity <u> (migration; the second seed paper)",
       .build = SHEARDIFF_SCENE(build_channel),
       .periodic_y = false,
       .measures = Measures::ChannelMigration,
       .check = SHEARDIFF_SCENE(check_channel),
       .default_frame_spacing = SHEARDIFF_SCENE(channel_frame_spacing),
       .planned_cell = SHEARDIFF_SCENE(channel_cell)},
  };
  return rows;
}

const SceneKind& scene_kind(const std::string& name) {
  for (const SceneKind& k : scene_registry())
    if (name == k.name) return k;
  throw ConfigError(fmt::format("scene.type: unknown scene \"{}\"", name));
}

std::string scenes_of_spheres() {
  std::string names;
  for (const SceneKind& k : scene_registry())
    if (k.spheres) names += fmt::format("{}`{}`", names.empty() ? "" : ", ", k.name);
  return names.empty() ? "no scene" : names;
}

std::string default_scene_name() {
  return scene_registry().front().name;
}

#ifndef SHEARDIFF_SCENE_NAMES_ONLY
Scene build_scene(const Config& cfg) {
  return scene_kind(cfg.scene.type).build(cfg);
}
#endif

}  // namespace sheardiff
