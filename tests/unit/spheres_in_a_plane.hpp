#pragma once
// Test helper: the spheres of a disc state, for the tests that check that the sphere engine
// restricted to one plane is the disc engine.
#include "sheardiff/core/particles.hpp"

namespace sheardiff::testing_3d {

// The same centres at height z, the same radii, species and motions.
inline Particles3 lift(const Particles& p2, double z) {
  Particles3 p;
  p.resize(p2.size());
  p.n_mobile = p2.n_mobile;
  for (std::size_t i = 0; i < p2.size(); ++i) {
    p.position[i] = Space3(p2.position[i].x(), p2.position[i].y(), z);
    p.unwrapped[i] = Space3(p2.unwrapped[i].x(), p2.unwrapped[i].y(), z);
  }
  p.radius = p2.radius;
  p.species = p2.species;
  p.motion = p2.motion;
  return p;
}

}  // namespace sheardiff::testing_3d
