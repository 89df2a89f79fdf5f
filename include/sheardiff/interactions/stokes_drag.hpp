#pragma once
#include "sheardiff/core/dimension.hpp"

namespace sheardiff {

// One-body Stokes drag against the imposed flow (ImposedFlow): F = -3 pi d (u - v_inf),
// T = -pi d^3 (omega - omega_inf), eta = 1. Wall particles feel none (permeable walls).
struct StokesDrag {
  static Vec3 resistance(double radius) {
    const double d = 2.0 * radius;
    return {3.0 * kPi * d, 3.0 * kPi * d, kPi * d * d * d};
  }
  // The same sphere's drag on all three translations and rotations.
  static Vec6 resistance_3d(double radius) {
    const double d = 2.0 * radius;
    Vec6 r;
    r << 3.0 * kPi * d, 3.0 * kPi * d, 3.0 * kPi * d, kPi * d * d * d, kPi * d * d * d,
        kPi * d * d * d;
    return r;
  }
  template <class D>
  static typename D::Body resistance_of(double radius) {
    if constexpr (D::space == 2)
      return resistance(radius);
    else
      return resistance_3d(radius);
  }
};

}  // namespace sheardiff
