// The scene registry: one row per scene. A new scene is its builder in src/scene/NAME.cpp plus
// one row here (and its declaration below).
//
// The config parser's fuzz target (tests/fuzz) compiles this file alone for the scene names, with
// SHEARDIFF_SCENE_NAMES_ONLY: then no builder is linked.
#include "sheardiff/scene/registry.hpp"

#include <fmt/format.h>

#ifndef SHEARDIFF_SCENE_NAMES_ONLY
#include "sheardiff/scene/scene.hpp"
#define SHEARDIFF_SCENE_BUILDER(f) f
#else
#define SHEARDIFF_SCENE_BUILDER(f) nullptr
#endif

namespace sheardiff {

// Builders, one file each in src/scene.
Scene build_simple_shear(const Config& cfg);
Scene build_pressure_shear(const Config& cfg);
Scene build_channel(const Config& cfg);

const std::vector<SceneKind>& scene_registry() {
  static const std::vector<SceneKind> rows = {
      {"simple_shear",
       "`simple_shear` = Lees-Edwards periodic cell at fixed area fraction and shear rate",
       SHEARDIFF_SCENE_BUILDER(build_simple_shear), /*periodic_y=*/true,
       /*measured_from_steady_state=*/false},
      {"pressure_shear",
       "`pressure_shear` = plane shear between rough walls, the top wall floating under the load "
       "P Lx lz (the packing dilates to phi(J))",
       SHEARDIFF_SCENE_BUILDER(build_pressure_shear), /*periodic_y=*/false,
       /*measured_from_steady_state=*/true},
      {"channel",
       "`channel` = pressure-driven flow of monodisperse discs between two fixed rows of wall "
       "discs at a fixed mean velocity <u> (migration; the second seed paper)",
       SHEARDIFF_SCENE_BUILDER(build_channel), /*periodic_y=*/false,
       /*measured_from_steady_state=*/false, /*channel_flow=*/true},
  };
  return rows;
}

const SceneKind& scene_kind(const std::string& name) {
  for (const SceneKind& k : scene_registry())
    if (name == k.name) return k;
  throw ConfigError(fmt::format("scene.type: unknown scene \"{}\"", name));
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
