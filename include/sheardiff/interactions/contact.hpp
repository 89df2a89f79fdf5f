#pragma once
#include <algorithm>
#include <cmath>
#include <optional>

#include "sheardiff/config.hpp"
#include "sheardiff/core/pair_history.hpp"
#include "sheardiff/interactions/pair_law.hpp"

namespace sheardiff {

// Linear spring contact with Coulomb friction (docs/model.md section 5). Forces act in the
// 6-vector space (u_x, u_y, omega)_i, (u_x, u_y, omega)_j of the pair.
struct FrictionalContact {
  // State a contact carries from step to step (whether the pair touches is the pair's own,
  // PairHistory::touching).
  using History = TangentialSpring;    // core/pair_history.hpp
  using History3 = TangentialSpring3;  // between two spheres

  double kn = 1e4;
  double kt = 5e3;
  double mu = 0.5;
  // LF_DEM's convention: each pair's kn and kt scaled by its mean radius over the small one,
  // (a_i + a_j) / d (1, 1.2, 1.4 for small-small, small-large, large-large at 1 : 1.4).
  bool scale_with_radius = false;
  // Which sliding contacts stick once the implicit step's slip s is solved (contact.stick_rule).
  // A sliding contact's stretch xi is at the cap, so its trial stretch xi + s dt ends inside the
  // cone when 2 xi . s + dt |s|^2 < 0. Unloading sticks every contact with xi . s < 0. Coulomb
  // sticks those inside the cone and those whose slip along -xi exceeds |xi| (-xi . s dt >=
  // |xi|^2): a reversal through zero, which left sliding would flip between +cap and -cap every
  // step (docs/low_j.md). For discs (s parallel to xi) the two are the same set; for spheres
  // Coulomb leaves sliding a contact whose slip turns its stretch sideways outside the cone.
  enum class StickRule { Unloading, Coulomb };
  StickRule stick_rule = StickRule::Unloading;
  // Between spheres a sliding contact's spring is at the cap along its stretch xi but not across
  // it: a slip normal to xi in the tangent plane turns the spring, and with it the friction
  // force, and Coulomb caps only its length. The capped law's tangent across xi over a step is
  // kt cap / |trial stretch| (the radial return's). With `sideways` (contact.sliding_stiffness)
  // the implicit step puts it in the matrix, with the ratio of the contact's last cap (a step
  // earlier, what is known when the step is assembled); without it the direction of the force
  // is explicit, and where the load exceeds the cap by less than the cap itself its correction
  // overshoots and grows from step to step until the slip reverses and the contact sticks.
  bool sideways = false;

  static std::optional<FrictionalContact> from(const Config& cfg) {
    const double k = cfg.contact.ktilde;
    return FrictionalContact{
        k,
        cfg.contact.kt_ratio * k,
        cfg.contact.mu,
        cfg.contact.stiffness == "mean_radius",
        cfg.contact.stick_rule == "coulomb" ? StickRule::Coulomb : StickRule::Unloading,
        cfg.contact.sliding_stiffness == "sideways"};
  }

  bool has_friction() const { return mu > 0.0 && kt > 0.0; }
  template <class Geometry>  // PairGeometry or PairGeometry3
  double scale(const Geometry& g) const {
    return scale_with_radius ? g.ai + g.aj : 1.0;
  }
  template <class Geometry>
  double kn_of(const Geometry& g) const {
    return kn * scale(g);
  }
  template <class Geometry>
  double kt_of(const Geometry& g) const {
    return kt * scale(g);
  }

  static Vec6 normal_mode(const PairGeometry& g) { return sheardiff::normal_mode(g); }
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

  // ---- The pair-law contract (pair_law.hpp) ----
  double range_factor() const { return 1.0; }
  template <class Geometry>
  bool acts(const Geometry&, bool touching) const {
    return touching;
  }
  void add_block(const PairGeometry& g, const History& h, bool, double dt_implicit,
                 PairBlock& b) const {
    const bool friction = has_friction();
    b.add_force(spring_force(g, friction ? h.xi : 0.0));
    // Sliding is what the last Coulomb cap decided, not a re-test of |xi| against the new
    // overlap: a growing overlap would otherwise turn a sliding contact sticky.
    b.sliding = friction && h.sliding;
    if (dt_implicit > 0.0) b.add_matrix(dt_implicit * stiffness(g, b.sliding));
  }
  bool resistive() const { return false; }
  bool keeps_history() const { return has_friction(); }
  // Springs stretch with the slip at the geometry of the start of the step ...
  void advance(History& h, const PairGeometry& g, const Vec6& u, double dt) const {
    h.xi += slip_rate(g, u) * dt;
  }
  // ... and are capped by Coulomb at its end, where their force is next evaluated, so that
  // kt |xi| <= mu kn overlap holds at every force evaluation.
  void cap(History& h, const PairGeometry& g) const { h.sliding = apply_coulomb(g, h.xi); }
  // Implicit springs: a contact that entered the step sliding but whose solved slip u runs
  // against its stretch unloads its spring, so it sticks (Coulomb: |f_t| < mu f_n). Returns
  // whether it changed. Both stick rules are this test for discs (s along xi: inside the cone
  // for a reversal below 2 |xi|, through zero above |xi|), so dt is not needed.
  bool stick_after_slip(History& h, const PairGeometry& g, const Vec6& u, double) const {
    if (!h.sliding || !(slip_rate(g, u) * h.xi < 0.0)) return false;
    h.sliding = false;
    return true;
  }
  // ---- Three dimensions (spheres; the law's vector form) ----
  // The tangential spring is a vector xi in the plane normal to n; in a pair of the x-y plane it
  // is the disc's xi times t = z x n. Pair space: (u, omega)_i, (u, omega)_j.
  using Vec12 = sheardiff::Vec12;
  using SlipMode3 = Eigen::Matrix<double, 3, 12>;
  static Vec12 normal_mode_3d(const PairGeometry3& g) { return sheardiff::normal_mode(g); }
  // Slip velocity v_s = -W U = (I - n n^T)(u_j - u_i) - (a_i omega_i + a_j omega_j) x n.
  static SlipMode3 slip_mode_3d(const PairGeometry3& g) {
    const Mat3 plane = Mat3::Identity() - g.n * g.n.transpose();
    const Mat3 nx = cross_matrix(g.n);
    SlipMode3 w;
    w << plane, -g.ai * nx, -plane, -g.aj * nx;
    return w;
  }
  static Space3 slip_velocity_3d(const PairGeometry3& g, const Vec12& u) {
    return -slip_mode_3d(g) * u;
  }
  // Spring force and torque on the pair: the normal spring and kt xi on i (-kt xi on j), whose
  // torques are a n x kt xi on both spheres.
  Vec12 spring_force_3d(const PairGeometry3& g, const Space3& xi) const {
    return scale(g) *
           (-kn * g.overlap() * normal_mode_3d(g) + kt * slip_mode_3d(g).transpose() * xi);
  }
  // Whether a sliding spring xi keeps a stiffness across itself (`sideways`, and a direction).
  bool stiff_across(const Space3& xi) const {
    return has_friction() && sideways && xi.squaredNorm() > 0.0;
  }
  // Sliding, with `sideways`, the stiffness across a stretch xi in the tangent plane is
  // across x kt.
  Mat12 stiffness_3d(const PairGeometry3& g, bool sliding, const Space3& xi = Space3::Zero(),
                     double across = 1.0) const {
    const Vec12 m = normal_mode_3d(g);
    Mat12 k = kn * m * m.transpose();
    if (has_friction() && !sliding) {
      const SlipMode3 w = slip_mode_3d(g);
      k += kt * w.transpose() * w;
    } else if (stiff_across(xi)) {
      const Vec12 r = slip_mode_3d(g).transpose() * g.n.cross(xi.normalized());
      k += across * kt * r * r.transpose();
    }
    return scale(g) * k;
  }
  // The spring stretches with the slip, then turns with the pair: it is brought back into the
  // plane normal to the new n with its length kept (what rotates with the contact).
  static void advance_3d(Space3& xi, const PairGeometry3& g, const Vec12& u, double dt) {
    xi += slip_velocity_3d(g, u) * dt;
  }
  static void turn_with_pair(Space3& xi, const Space3& n) {
    const double length = xi.norm();
    const Space3 in_plane = xi - n.dot(xi) * n;
    const double l = in_plane.norm();
    xi = l > 0.0 ? Space3(in_plane * (length / l)) : Space3::Zero();
  }
  // Coulomb: |kt xi| <= mu kn overlap, the spring shortened along itself; returns whether it
  // slides.
  bool apply_coulomb_3d(const PairGeometry3& g, Space3& xi) const {
    if (!has_friction()) {
      xi.setZero();
      return false;
    }
    const double cap = mu * kn * std::max(g.overlap(), 0.0) / kt, length = xi.norm();
    if (length > cap) {
      xi *= cap / length;
      return true;
    }
    return false;
  }

  // The contract in three dimensions, as in two: sliding is what the last cap decided; the
  // spring stretches at the start geometry, then turns with the pair and is capped at the end.
  void add_block(const PairGeometry3& g, const History3& h, bool, double dt_implicit,
                 PairBlock3& b) const {
    const bool friction = has_friction();
    b.add_force(spring_force_3d(g, friction ? h.xi : Space3::Zero()));
    b.sliding = friction && h.sliding;
    if (dt_implicit > 0.0) b.add_matrix(dt_implicit * stiffness_3d(g, b.sliding, h.xi, h.across));
  }
  void advance(History3& h, const PairGeometry3& g, const Vec12& u, double dt) const {
    advance_3d(h.xi, g, u, dt);
  }
  void cap(History3& h, const PairGeometry3& g) const {
    turn_with_pair(h.xi, g.n);
    const double trial = h.xi.norm();
    h.sliding = apply_coulomb_3d(g, h.xi);
    h.across = h.sliding && trial > 0.0 ? h.xi.norm() / trial : 1.0;
  }
  // The stick rule of spheres over a step dt (stick_rule above).
  bool sticks_3d(const Space3& xi, const Space3& s, double dt) const {
    const double along = xi.dot(s);
    if (!(along < 0.0)) return false;
    if (stick_rule == StickRule::Unloading) return true;
    return 2.0 * along + dt * s.squaredNorm() < 0.0 || -along * dt >= xi.squaredNorm();
  }
  bool stick_after_slip(History3& h, const PairGeometry3& g, const Vec12& u, double dt) const {
    if (!h.sliding || !sticks_3d(h.xi, slip_velocity_3d(g, u), dt)) return false;
    h.sliding = false;
    return true;
  }

  void add_stability(double, StabilityTerms& s) const {
    s.normal_stiffness += kn;
    if (has_friction()) s.tangential_stiffness += kt;
  }
  bool needs_rotations() const { return has_friction(); }
};

}  // namespace sheardiff
