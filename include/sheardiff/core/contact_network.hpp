#pragma once
// The contacts of one configuration, as observers measure them and the trajectory stores them.
#include <array>
#include <vector>

namespace sheardiff {

// Per-frame contact network: contact k joins particles pairs[k] (indices into the particle
// group, i < j not implied). Forces are those of the contact springs at the frame: the normal
// force kn * overlap (repulsive > 0) and the tangential force on j along t = z x n (n from i to
// j), in P d^2; sliding: 1 at the Coulomb limit, else 0.
struct ContactNetwork {
  std::vector<std::array<int, 2>> pairs;
  std::vector<double> normal_force;
  std::vector<double> tangential_force;
  std::vector<int> sliding;
};

}  // namespace sheardiff
