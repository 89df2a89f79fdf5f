#pragma once
#include <optional>

#include "sheardiff/config.hpp"
#include "sheardiff/interactions/pair_law.hpp"

namespace sheardiff {

// Resistance coefficients of one pair, already multiplied by 6 pi eta (eta = 1).
struct PairResistance {
  double xa = 0, ya = 0;                      // squeeze, shear
  double beta_i = 0, beta_j = 0;              // shear-rotation coupling
  double gam_ii = 0, gam_jj = 0, gam_ij = 0;  // pump / rotation

  // The 6x6 block R_pair in the order (u_x, u_y, omega)_i, (u_x, u_y, omega)_j
  // (docs/model.md section 4); the pair's force and torque are -R_pair U.
  Mat6 matrix(const Vec2& n, const Vec2& t) const;
  // The same law between two spheres in three dimensions, in its vector form (Mari et al. 2014):
  // the 12x12 block in the order (u, omega)_i, (u, omega)_j, with A = XA n n^T + YA (I - n n^T),
  // the shear-rotation coupling through n x . and the rotational modes on the plane normal to
  // n. Restricted to (u_x, u_y, omega_z) of a pair in the x-y plane it is matrix(n, z x n).
  Mat12 matrix_3d(const Space3& n) const;
};

// Leading singular lubrication between two discs of a monolayer (Ball & Melrose modes),
// regularised by delta; also gives the contact dashpots (the same law frozen at h = 0).
struct Lubrication {
  using History = NoHistory;

  double delta = 0.01;
  double h_max = 0.5;
  // Off: squeeze mode only, so lubrication exerts no torque and needs no rotational unknowns.
  bool tangential = true;

  static std::optional<Lubrication> from(const Config& cfg) {
    if (!cfg.lubrication.enabled) return std::nullopt;
    return Lubrication{cfg.lubrication.delta, cfg.lubrication.h_max, cfg.lubrication.tangential};
  }

  bool acts(double h) const { return h < h_max; }
  // Coefficients at reduced gap h; h <= 0 (contact) is evaluated at h = 0 (dashpots).
  PairResistance coefficients(double ai, double aj, double h) const;

  // ---- The pair-law contract (pair_law.hpp) ----
  // h_max is a reduced gap, 2 r / (a_i + a_j) - 2.
  double range_factor() const { return 1.0 + 0.5 * h_max; }
  // A touching pair keeps its dashpots even if the geometry of a predictor moved it apart.
  template <class Geometry>
  bool acts(const Geometry& g, bool touching) const {
    return touching || acts(g.h);
  }
  void add_block(const PairGeometry& g, const History&, bool, double, PairBlock& b) const {
    b.add_matrix(coefficients(g.ai, g.aj, g.h).matrix(g.n, g.t));
  }
  void add_block(const PairGeometry3& g, const History&, bool, double, PairBlock3& b) const {
    b.add_matrix(coefficients(g.ai, g.aj, g.h).matrix_3d(g.n));
  }
  bool resistive() const { return true; }
  bool keeps_history() const { return false; }
  template <class Geometry, class PairVelocity>
  void advance(History&, const Geometry&, const PairVelocity&, double) const {}
  template <class Geometry>
  void cap(History&, const Geometry&) const {}
  void add_stability(double a, StabilityTerms& s) const {
    const PairResistance r = coefficients(a, a, 0.0);
    s.normal_damping += r.xa;
    s.tangential_damping += r.ya;
  }
  bool needs_rotations() const { return tangential; }
};

}  // namespace sheardiff
