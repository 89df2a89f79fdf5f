#pragma once
// The contacts of one configuration, as observers measure them and the trajectory stores them.
#include <array>
#include <vector>

namespace sheardiff {

// Per-frame contact network: contact k joins particles pairs[k] (indices into the particle
// group, i < j not implied). Forces are those of the contact springs at the frame, in P d^2: the
// normal force kn * overlap (repulsive > 0) and the tangential spring force on j, for discs one
// value per contact along t = z x n (n from i to j), for spheres the vector (x, y, z) in the
// plane normal to n, three values per contact (`components`); sliding: 1 at the Coulomb limit,
// else 0.
struct ContactNetwork {
  std::vector<std::array<int, 2>> pairs;
  std::vector<double> normal_force;
  std::vector<double> tangential_force;  // components values per contact
  std::vector<int> sliding;
  int components = 1;  // 1 (discs) or 3 (spheres)
};

}  // namespace sheardiff
