// Simple shear (Lees-Edwards periodic cell at fixed area or volume fraction and shear rate): the
// engine's validation scene, of discs or of spheres.
#include <cmath>

#include "sheardiff/scene/scene.hpp"
#include "sheardiff/setup/random_packing.hpp"

namespace sheardiff {

Scene build_simple_shear(const Config& cfg) {
  Packing pk = initial_packing(cfg, true);
  Scene sc;
  sc.particles.resize(pk.position.size());
  sc.particles.n_mobile = pk.position.size();
  sc.particles.position = pk.position;
  sc.particles.unwrapped = pk.position;
  sc.particles.radius = pk.radius;
  sc.particles.species = pk.species;
  sc.box.lx = pk.lx;
  sc.box.ly = pk.ly;
  sc.box.lees_edwards = true;
  sc.box.le_offset = pk.tilt;
  sc.flow.gammadot = cfg.flow.j;
  sc.flow.y0 = 0.0;
  return sc;
}

}  // namespace sheardiff

namespace sheardiff {

PlannedCell simple_shear_3d_cell(const Config& cfg) {
  // The random start's cell, without placing the spheres.
  const SphereCell c =
      sphere_packing_cell(cfg.particles.n, cfg.particles.mix, cfg.particles.size_ratio,
                          cfg.particles.phi_init_spheres, cfg.particles.aspect);
  return {.lx = c.l, .ly = c.ly, .lz = c.l};
}

Scene3 build_simple_shear_3d(const Config& cfg) {
  const SpherePacking pk = random_sphere_packing(
      cfg.particles.n, cfg.particles.mix, cfg.particles.size_ratio, cfg.particles.phi_init_spheres,
      cfg.particles.aspect, true, static_cast<std::uint64_t>(cfg.run.seed) ^ 0x51ab7c3d9e3779b9ULL);
  Scene3 sc;
  Particles3& p = sc.particles;
  p.resize(pk.position.size());
  p.n_mobile = pk.position.size();
  p.position = pk.position;
  p.unwrapped = pk.position;
  p.radius = pk.radius;
  p.species = pk.species;
  sc.box.lx = sc.box.lz = pk.l;
  sc.box.ly = pk.ly;
  sc.box.lees_edwards = true;
  sc.flow.gammadot = cfg.flow.j;
  sc.flow.y0 = 0.0;
  return sc;
}

}  // namespace sheardiff
