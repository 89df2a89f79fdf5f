#pragma once
#include <type_traits>

#include "sheardiff/core/dimension.hpp"

namespace sheardiff {

// The simulation cell. x is always periodic with length Lx. In y the cell is either
// Lees-Edwards periodic (simple shear: the image at +Ly moves with the imposed flow's velocity
// difference across Ly, ImposedFlow::image_velocity_x) or bounded by walls (y extent given by
// the wall bodies, ly unused for images).
struct Box {
  double lx = 1.0;
  double ly = 1.0;
  bool lees_edwards = false;
  // Unwrapped Lees-Edwards offset: x shift of the image at +Ly, = gammadot * Ly * t.
  double le_offset = 0.0;

  // Shift of the periodic image (kx, ky) at the current time.
  Vec2 image_shift(int kx, int ky) const { return {kx * lx + ky * le_offset, ky * ly}; }
};

// The cell of spheres: the same in x and y, and periodic in z (the vorticity direction) with
// length lz.
struct Box3 : Box {
  double lz = 1.0;

  Space3 image_shift(int kx, int ky, int kz) const {
    return {kx * lx + ky * le_offset, ky * ly, kz * lz};
  }
};

template <class D>
using BoxOf = std::conditional_t<D::space == 2, Box, Box3>;

}  // namespace sheardiff
