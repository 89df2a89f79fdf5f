// Simple shear (Lees-Edwards periodic cell at fixed area fraction and shear rate): the engine's
// validation scene.
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
