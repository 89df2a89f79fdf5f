#pragma once
#include "sheardiff/interactions/pair_geometry.hpp"

namespace sheardiff {

// State a contact carries from step to step.
struct ContactHistory {
  bool active = false;  // h <= 0 at the start of the current step
  double xi = 0.0;      // scalar tangential spring stretch (2D)
  bool sliding = false; // the last step capped xi at the Coulomb limit
};

// Linear spring contact with Coulomb friction (docs/model.md section 5). Forces act in the
// 6-vector space (u_x, u_y, omega)_i, (u_x, u_y, omega)_j of the pair.
struct FrictionalContact {
  double kn = 1e4;
  double kt = 5e3;
  double mu = 0.5;
  // LF_DEM's convention: each pair's kn and kt scaled by its mean radius over the small one,
  // (a_i + a_j) / d (1, 1.2, 1.4 for small-small, small-large, large-large at 1 : 1.4).
  bool scale_with_radius = false;

  bool has_friction() const { return mu > 0.0 && kt > 0.0; }
  double scale(const PairGeometry& g) const { return scale_with_radius ? g.ai + g.aj : 1.0; }
  double kn_of(const PairGeometry& g) const { return kn * scale(g); }
  double kt_of(const PairGeometry& g) const { return kt * scale(g); }

  // Normal direction in pair space: d(overlap)/dt = normal_mode . U.
  static Vec6 normal_mode(const PairGeometry& g) {
    Vec6 m;
    m << g.n, 0.0, -g.n, 0.0;
    return m;
  }
  // Slip direction in pair space: slip rate v_s = -slip_mode . U.
  static Vec6 slip_mode(const PairGeometry& g) {
    Vec6 w;
    w << g.t, g.ai, -g.t, g.aj;
    return w;
  }
  // Slip rate t.(u_j - u_i) - (a_i omega_i + a_j omega_j).
  static double slip_rate(const PairGeometry& g, const Vec6& u) { return -slip_mode(g).dot(u); }

  // Spring force and torque on the pair (generalised 6-vector) for overlap and stretch xi.
  Vec6 spring_force(const PairGeometry& g, double xi) const {
    return scale(g) * (-kn * g.overlap() * normal_mode(g) + kt * xi * slip_mode(g));
  }
  // The linearised spring stiffness: the force after a step dt is spring_force - dt K U.
  // A sliding contact has no tangential stiffness (its force is fixed at the Coulomb cap).
  Mat6 stiffness(const PairGeometry& g, bool sliding) const {
    const Vec6 m = normal_mode(g);
    Mat6 k = kn * m * m.transpose();
    if (has_friction() && !sliding) {
      const Vec6 w = slip_mode(g);
      k += kt * w * w.transpose();
    }
    return scale(g) * k;
  }
  bool at_coulomb_limit(const PairGeometry& g, double xi) const {
    return kt * std::abs(xi) >= mu * kn * g.overlap() * (1.0 - 1e-12);
  }
  // Coulomb: |kt xi| <= mu kn overlap (the pair's scale cancels); returns whether it slides.
  bool apply_coulomb(const PairGeometry& g, double& xi) const {
    if (!has_friction()) {
      xi = 0.0;
      return false;
    }
    const double cap = mu * kn * std::max(g.overlap(), 0.0) / kt;
    if (std::abs(xi) > cap) {
      xi = std::copysign(cap, xi);
      return true;
    }
    return false;
  }
};

}  // namespace sheardiff
