#pragma once
#include "sheardiff/core/types.hpp"

namespace sheardiff {

// One-body Stokes drag against the imposed flow: F = -3 pi d (u - v_inf),
// T = -pi d^3 (omega - omega_inf), eta = 1. Wall particles feel none (permeable walls).
struct StokesDrag {
  static Vec3 resistance(double radius) {
    const double d = 2.0 * radius;
    return {3.0 * kPi * d, 3.0 * kPi * d, kPi * d * d * d};
  }
};

// The imposed simple shear v_inf = (gammadot (y - y0), 0), omega_inf = -gammadot / 2.
struct ShearFlow {
  double gammadot = 0.0;
  double y0 = 0.0;
  Vec3 velocity(const Vec2& x) const { return {gammadot * (x.y() - y0), 0.0, -0.5 * gammadot}; }
};

}  // namespace sheardiff
