#pragma once
#include <optional>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/core/box.hpp"
#include "sheardiff/core/imposed_flow.hpp"
#include "sheardiff/core/particles.hpp"
#include "sheardiff/core/walls.hpp"
#include "sheardiff/interactions/fluid_layer.hpp"
#include "sheardiff/scene/registry.hpp"

namespace sheardiff {

// What a scene hands to the engine: particles, cell, imposed flow and, if any, wall bodies.
struct Scene {
  Particles particles;
  Box box;
  ImposedFlow flow;
  std::optional<WallBodies> walls;
  std::optional<FluidLayer> fluid;  // the channel's fluid, solved with the particles
};

// The scene cfg asks for, built.
Scene build_scene(const Config& cfg);

}  // namespace sheardiff
