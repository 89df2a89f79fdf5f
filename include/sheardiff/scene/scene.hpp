#pragma once
#include <optional>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/core/box.hpp"
#include "sheardiff/core/imposed_flow.hpp"
#include "sheardiff/core/particles.hpp"
#include "sheardiff/core/walls.hpp"
#include "sheardiff/scene/registry.hpp"

namespace sheardiff {

// The grid of a channel's fluid layer (interactions/fluid_layer.hpp): the gap y_lo .. y_hi with
// cells elements across it, the slab lx x lz, and how far a particle may move in y between two
// pattern rebuilds (reach).
struct FluidGrid {
  double y_lo = 0.0, y_hi = 0.0;
  int cells = 0;
  double lx = 0.0, lz = 0.0, reach = 0.0;
};

// What a scene hands to the engine: particles, cell, imposed flow and, if any, wall bodies and
// a fluid solved with the particles.
struct Scene {
  Particles particles;
  Box box;
  ImposedFlow flow;
  std::optional<WallBodies> walls;
  std::optional<FluidGrid> fluid;  // the channel's fluid, solved with the particles
};

// The scene cfg asks for, built.
Scene build_scene(const Config& cfg);

}  // namespace sheardiff
