#pragma once
#include <optional>

#include "sheardiff/config.hpp"
#include "sheardiff/core/box.hpp"
#include "sheardiff/core/particles.hpp"
#include "sheardiff/integrator/dynamics.hpp"

namespace sheardiff {

// What a scene hands to the engine: particles, cell, imposed flow and, if any, wall bodies.
struct Scene {
  Particles particles;
  Box box;
  ShearFlow flow;
  std::optional<WallBodies> walls;
};

// Lees-Edwards periodic cell at fixed area fraction and shear rate (volume imposed).
Scene build_simple_shear(const Config& cfg);
// Plane shear between two rough walls of frozen particles, periodic in x; the bottom wall
// fixed, the top wall driven at gammadot H and floating in y under the load P Lx lz.
Scene build_pressure_shear(const Config& cfg);
// Dispatch on scene.type.
Scene build_scene(const Config& cfg);

}  // namespace sheardiff
