#pragma once
#include "sheardiff/core/types.hpp"

namespace sheardiff {

// One-body Stokes drag against the imposed flow (ImposedFlow): F = -3 pi d (u - v_inf),
// T = -pi d^3 (omega - omega_inf), eta = 1. Wall particles feel none (permeable walls).
struct StokesDrag {
  static Vec3 resistance(double radius) {
    const double d = 2.0 * radius;
    return {3.0 * kPi * d, 3.0 * kPi * d, kPi * d * d * d};
  }
};

}  // namespace sheardiff
