#pragma once
// The fluid of a pressure-driven channel as unknowns of the force balance (docs/channel.md,
// "The fluid solve"). Its mean velocity across the channel is U_f(y) = U_ref(y) + w(y): U_ref,
// the Poiseuille profile of the imposed flow with the channel's mean velocity <u>, and w, a
// deviation carried by piecewise-linear elements on a grid across the gap, zero at both walls.
// The fluid obeys the 1D Stokes balance eta U_f'' + G = (the drag density of the particles),
// with G = -dp/dx the pressure gradient, an output: it is the multiplier that holds the
// channel's mean fluid velocity at <u> (the deviation's integral at zero).
//
// Written as one dissipation functional (Stokes drag of each particle against U_f at its centre,
// the rotational drag against -U_f'/2, the fluid's viscous dissipation over the slab
// Lx x H x l_z), the coupled system stays symmetric positive definite: the particle rows get the
// fluid's velocity, the fluid rows the particles' drag (the reaction of their rotational drag
// acts on the fluid as a couple, which a 1D balance without it would drop and lose symmetry).
#include <cstddef>
#include <utility>
#include <vector>

#include "sheardiff/core/imposed_flow.hpp"
#include "sheardiff/core/particles.hpp"
#include "sheardiff/core/types.hpp"
#include "sheardiff/interactions/system_entries.hpp"

namespace sheardiff {

class FluidLayer {
 public:
  // The gap y_lo .. y_hi (no slip at both), cells elements across it, the slab's length lx and
  // thickness lz, eta = 1. reach: how far a particle may move in y between two pattern rebuilds
  // (half the neighbour skin).
  FluidLayer(double y_lo, double y_hi, int cells, double lx, double lz, double reach);

  int cells() const { return cells_; }
  // Unknowns: the interior nodes 1 .. cells - 1.
  std::size_t unknowns() const { return static_cast<std::size_t>(cells_ - 1); }
  double y_lo() const { return y_lo_; }
  double y_hi() const { return y_hi_; }
  double spacing() const { return h_; }
  double node_y(int k) const { return y_lo_ + k * h_; }

  // The entries (row >= col, global indices) the layer adds to a system whose fluid unknowns
  // start at `base`, for mobile particles at heights y (one per mobile particle).
  std::vector<std::pair<int, int>> pattern(const std::vector<double>& y, int dof, int base) const;
  // Adds the layer's blocks and right-hand side (the particles' drag on the fluid against the
  // reference flow, the fluid's viscous term and the reference profile's pressure gradient G0).
  void assemble(const Particles& p, const ImposedFlow& reference, int dof, int base,
                SystemEntries& system) const;
  // The pressure gradient's generalised force on the fluid unknowns (per unit G): e_k =
  // Lx lz int phi_k dy; e . w = Lx lz int w dy, the deviation's flux.
  VecX load(std::size_t total_unknowns, int base) const;
  // The pressure gradient of the reference profile, 12 eta <u> / H^2.
  static double poiseuille_gradient(const ImposedFlow& reference);

  // The deviation w and its slope at height y from the interior-node values.
  double deviation(const std::vector<double>& w, double y) const;
  double deviation_slope(const std::vector<double>& w, double y) const;
  // Largest |w'| over the grid.
  double max_deviation_slope(const std::vector<double>& w) const;

 private:
  // Element of y (clamped into the gap) and the local coordinate s in [0, 1].
  int element(double y, double& s) const;
  // Global index of node k (interior: 1 .. cells - 1), -1 for the walls.
  int unknown(int k, int base) const { return k <= 0 || k >= cells_ ? -1 : base + k - 1; }

  double y_lo_, y_hi_;
  int cells_;
  double h_, lx_, lz_, reach_;
};

}  // namespace sheardiff
