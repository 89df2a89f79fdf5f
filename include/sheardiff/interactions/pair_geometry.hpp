#pragma once
#include <cmath>
#include <type_traits>

#include "sheardiff/core/dimension.hpp"

namespace sheardiff {

// Geometry of one pair (i, j): the only input a pair law needs besides its parameters.
struct PairGeometry {
  double ai = 0.5, aj = 0.5;  // radii
  double s = 1.0;             // ai + aj
  double r = 1.0;             // centre distance
  double h = 0.0;             // reduced gap 2 r / s - 2 (negative in contact)
  Vec2 n = Vec2::UnitX();     // unit vector from i to j
  Vec2 t = Vec2::UnitY();     // z x n

  double overlap() const { return s - r; }

  static PairGeometry make(const Vec2& rij, double ai, double aj) {
    PairGeometry g;
    g.ai = ai;
    g.aj = aj;
    g.s = ai + aj;
    g.r = rij.norm();
    g.n = rij / g.r;
    g.t = perp(g.n);
    g.h = 2.0 * g.r / g.s - 2.0;
    return g;
  }
};

// The same for two spheres in three dimensions (no t: the tangent plane is normal to n).
struct PairGeometry3 {
  double ai = 0.5, aj = 0.5;
  double s = 1.0;
  double r = 1.0;
  double h = 0.0;
  Space3 n = Space3::UnitX();

  double overlap() const { return s - r; }

  static PairGeometry3 make(const Space3& rij, double ai, double aj) {
    PairGeometry3 g;
    g.ai = ai;
    g.aj = aj;
    g.s = ai + aj;
    g.r = rij.norm();
    g.n = rij / g.r;
    g.h = 2.0 * g.r / g.s - 2.0;
    return g;
  }
};

template <class D>
using PairGeometryOf = std::conditional_t<D::space == 2, PairGeometry, PairGeometry3>;

}  // namespace sheardiff
