#pragma once
#include "sheardiff/interactions/pair_geometry.hpp"

namespace sheardiff {

// Resistance coefficients of one pair, already multiplied by 6 pi eta (eta = 1).
struct PairResistance {
  double xa = 0, ya = 0;                    // squeeze, shear
  double beta_i = 0, beta_j = 0;            // shear-rotation coupling
  double gam_ii = 0, gam_jj = 0, gam_ij = 0;  // pump / rotation

  // The 6x6 block R_pair in the order (u_x, u_y, omega)_i, (u_x, u_y, omega)_j
  // (docs/model.md section 4); the pair's force and torque are -R_pair U.
  Mat6 matrix(const Vec2& n, const Vec2& t) const;
};

// Leading singular lubrication between two discs of a monolayer (Ball & Melrose modes),
// regularised by delta; also gives the contact dashpots (the same law frozen at h = 0).
struct Lubrication {
  double delta = 0.01;
  double h_max = 0.5;
  // Off: squeeze mode only, so lubrication exerts no torque and needs no rotational unknowns.
  bool tangential = true;

  bool acts(double h) const { return h < h_max; }
  // Coefficients at reduced gap h; h <= 0 (contact) is evaluated at h = 0 (dashpots).
  PairResistance coefficients(double ai, double aj, double h) const;
};

}  // namespace sheardiff
