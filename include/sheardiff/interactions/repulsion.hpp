#pragma once
#include <algorithm>
#include <cmath>
#include <optional>

#include "sheardiff/config.hpp"
#include "sheardiff/interactions/pair_law.hpp"

namespace sheardiff {

// Short-range electrostatic double-layer repulsion between the particle surfaces,
// F = F0 exp(-h / lambda) along the line of centres, h = r - (a_i + a_j) the surface gap (d) and
// lambda the Debye length (Mari et al. 2014 use it; docs/model.md section 5). Touching pairs
// feel F0: the double layers are at their closest and the contact spring takes the rest. Cut at
// h = cutoff lambda, where the force is exp(-cutoff) F0. Central: no torque, no history.
struct DoubleLayerRepulsion {
  using History = NoHistory;

  double f0 = 0.0;       // P d^2
  double lambda = 0.02;  // d
  double cutoff = 10.0;  // in Debye lengths

  static std::optional<DoubleLayerRepulsion> from(const Config& cfg) {
    if (!(cfg.repulsion.f0 > 0.0)) return std::nullopt;
    return DoubleLayerRepulsion{cfg.repulsion.f0, cfg.repulsion.lambda, cfg.repulsion.cutoff};
  }

  template <class Geometry>
  static double gap(const Geometry& g) {
    return g.r - g.s;
  }
  // Magnitude of the repulsion at surface gap h.
  double force(double h) const { return f0 * std::exp(-std::max(h, 0.0) / lambda); }

  // ---- The pair-law contract (pair_law.hpp) ----
  // The smallest pair has a_i + a_j = d, so a gap of cutoff lambda is (1 + cutoff lambda) s.
  double range_factor() const { return 1.0 + cutoff * lambda; }
  template <class Geometry>
  bool acts(const Geometry& g, bool) const {
    return gap(g) < cutoff * lambda;
  }
  template <class Geometry, class Block>
  void add_block(const Geometry& g, const History&, bool, double dt_implicit, Block& b) const {
    const double h = gap(g);
    const double f = force(h);
    const auto m = normal_mode(g);
    b.add_force(-f * m);
    // Over a step the gap grows by -dt m.U, so F changes by (F / lambda) dt m.U: the force
    // -F m at the end of the step is -F m - dt (F / lambda) m m^T U (none in contact).
    if (dt_implicit > 0.0 && h > 0.0) b.add_matrix(dt_implicit * (f / lambda) * m * m.transpose());
  }
  bool resistive() const { return false; }
  bool keeps_history() const { return false; }
  template <class Geometry, class PairVelocity>
  void advance(History&, const Geometry&, const PairVelocity&, double) const {}
  template <class Geometry>
  void cap(History&, const Geometry&) const {}
  // Its stiffness is largest at contact, F0 / lambda.
  void add_stability(double, StabilityTerms& s) const { s.normal_stiffness += f0 / lambda; }
  bool needs_rotations() const { return false; }
};

}  // namespace sheardiff
