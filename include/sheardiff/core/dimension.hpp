#pragma once
// The dimension of a run as a type: the engine's core (particles, box, neighbour list, pair laws,
// force balance) is written once over it and instantiated for discs in a monolayer (2) and for
// spheres (3). A particle's generalised velocity is its translational velocity followed by its
// angular velocity: (u_x, u_y, omega_z) in 2D, (u, omega) in 3D; a pair's is particle i's
// followed by particle j's.
#include <array>

#include "sheardiff/core/types.hpp"

namespace sheardiff {

template <int N>
struct Dimension;

template <>
struct Dimension<2> {
  static constexpr int space = 2;  // components of a position or a velocity
  static constexpr int body = 3;   // components of a generalised velocity (u, omega_z)
  using Point = Vec2;
  using Body = Vec3;
  using PairVector = Vec6;
  using PairMatrix = Mat6;
  using Images = std::array<int, 2>;
};

template <>
struct Dimension<3> {
  static constexpr int space = 3;
  static constexpr int body = 6;  // (u, omega)
  using Point = Space3;
  using Body = Vec6;
  using PairVector = Vec12;
  using PairMatrix = Mat12;
  using Images = std::array<int, 3>;
};

using Dim2 = Dimension<2>;
using Dim3 = Dimension<3>;

}  // namespace sheardiff
