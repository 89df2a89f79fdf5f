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

// What a scene of spheres hands to the engine (Dynamics3). No fluid layer: the channel is a disc
// scene.
struct Scene3 {
  Particles3 particles;
  Box3 box;
  ImposedFlow flow;
  std::optional<WallBodies> walls;
};

// The pressure cell of spheres: particles.N bidisperse spheres (d and particles.size_ratio d,
// mixed by particles.mix) placed at random and compressed in y to the volume fraction
// particles.phi_init_spheres (or, with 0, on a jittered cubic lattice loose enough for the
// largest, volume fraction ~0.2), in a cell particles.aspect times as high as wide, between two
// rough walls of frozen spheres of diameter d (a square lattice in x-z, centres jittered in y
// by walls.jitter radii), periodic in x and z (lx = lz); the bottom wall is fixed, the top wall
// floats under P lx lz (P = 1) and is driven at the imposed shear's velocity gammadot = flow.J
// at its height. The packing dilates or compacts under the wall to its steady volume fraction.
// Reproducible for run.seed.
Scene3 build_pressure_shear_3d(const Config& cfg);
// Its cell before the spheres are placed (checked before any work): lx = lz and the height
// between the walls' surfaces.
PlannedCell pressure_shear_3d_cell(const Config& cfg);

// Simple shear of spheres: particles.N bidisperse spheres placed at random and compressed to the
// volume fraction particles.phi_init_spheres in a cube (particles.aspect times as high as wide),
// periodic in x and z and Lees-Edwards periodic in y, sheared at gammadot = flow.J.
Scene3 build_simple_shear_3d(const Config& cfg);
PlannedCell simple_shear_3d_cell(const Config& cfg);

}  // namespace sheardiff
