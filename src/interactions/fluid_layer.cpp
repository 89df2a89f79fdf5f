#include "sheardiff/interactions/fluid_layer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sheardiff/interactions/stokes_drag.hpp"

namespace sheardiff {

FluidLayer::FluidLayer(double y_lo, double y_hi, int cells, double lx, double lz, double reach)
    : y_lo_(y_lo),
      y_hi_(y_hi),
      cells_(cells),
      h_((y_hi - y_lo) / cells),
      lx_(lx),
      lz_(lz),
      reach_(reach) {
  if (!(y_hi > y_lo) || cells < 2) throw std::invalid_argument("FluidLayer: empty grid");
}

int FluidLayer::element(double y, double& s) const {
  const double t = std::clamp((y - y_lo_) / h_, 0.0, static_cast<double>(cells_));
  const int e = std::min(static_cast<int>(t), cells_ - 1);
  s = t - e;
  return e;
}

std::vector<std::pair<int, int>> FluidLayer::pattern(const std::vector<double>& heights, int dof,
                                                     int base) const {
  std::vector<std::pair<int, int>> entries;
  for (int k = 1; k < cells_; ++k) {
    entries.emplace_back(unknown(k, base), unknown(k, base));
    if (k + 1 < cells_) entries.emplace_back(unknown(k + 1, base), unknown(k, base));
  }
  for (std::size_t i = 0; i < heights.size(); ++i) {
    // Every node whose element the particle can reach before the next rebuild.
    const double y = heights[i];
    const int lo = static_cast<int>(std::floor((y - reach_ - y_lo_) / h_));
    const int hi = static_cast<int>(std::ceil((y + reach_ - y_lo_) / h_));
    for (int k = std::max(lo, 1); k <= std::min(hi, cells_ - 1); ++k) {
      entries.emplace_back(unknown(k, base), dof * static_cast<int>(i));
      if (dof == 3) entries.emplace_back(unknown(k, base), dof * static_cast<int>(i) + 2);
    }
  }
  return entries;
}

void FluidLayer::assemble(const Particles& p, const ImposedFlow& reference, int dof, int base,
                          SystemEntries& system) const {
  // Viscous dissipation (1/2) eta lz lx int w'^2 dy of the deviation: the stiffness of linear
  // elements; the cross term with U_ref' integrates by parts (w = 0 at the walls) to
  // eta lz lx U_ref'' int phi_k dy = -G0 e_k on the right-hand side.
  const double stiff = lx_ * lz_ / h_;
  const double g0_load = -poiseuille_gradient(reference) * lx_ * lz_ * h_;
  for (int k = 1; k < cells_; ++k) {
    const int r = unknown(k, base);
    system.add_value(r, r, 2.0 * stiff);
    if (k + 1 < cells_) system.add_value(unknown(k + 1, base), r, -stiff);
    system.add_rhs(r, g0_load);
  }
  // Drag of each particle against U_f = U_ref + w at its centre (x) and omega_f = -U_f'/2
  // (rotation), written as zeta_c (u_c - ref_c - sum_k psi_k w_k)^2 / 2 for each component.
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    double s = 0.0;
    const int e = element(p.position[i].y(), s);
    const int nodes[2] = {unknown(e, base), unknown(e + 1, base)};
    const Vec3 zeta = StokesDrag::resistance(p.radius[i]);
    const Vec3 ref = reference.velocity(p.position[i]);
    struct Component {
      int row;
      double zeta, ref, psi[2];
    };
    Component comps[2] = {{dof * static_cast<int>(i), zeta.x(), ref.x(), {1.0 - s, s}},
                          {dof * static_cast<int>(i) + 2,
                           zeta.z(),
                           ref.z(),
                           {0.5 / h_, -0.5 / h_}}};  // psi = -phi'/2
    const int ncomp = dof == 3 ? 2 : 1;
    for (int c = 0; c < ncomp; ++c) {
      const Component& cp = comps[c];
      for (int a = 0; a < 2; ++a) {
        if (nodes[a] < 0) continue;
        system.add_value(nodes[a], cp.row, -cp.zeta * cp.psi[a]);
        system.add_rhs(nodes[a], -cp.zeta * cp.psi[a] * cp.ref);
        for (int b = 0; b < 2; ++b)
          if (nodes[b] >= 0 && nodes[b] <= nodes[a])
            system.add_value(nodes[a], nodes[b], cp.zeta * cp.psi[a] * cp.psi[b]);
      }
    }
  }
}

VecX FluidLayer::load(std::size_t total_unknowns, int base) const {
  VecX e = VecX::Zero(static_cast<Eigen::Index>(total_unknowns));
  for (int k = 1; k < cells_; ++k) e[unknown(k, base)] = lx_ * lz_ * h_;
  return e;
}

double FluidLayer::poiseuille_gradient(const ImposedFlow& reference) {
  // v = (y - y0)(gammadot + c (y - y0)): eta v'' = 2 c = -G0.
  return -2.0 * reference.curvature;
}

double FluidLayer::deviation(const std::vector<double>& w, double y) const {
  if (w.empty()) return 0.0;
  double s = 0.0;
  const int e = element(y, s);
  const auto at = [&](int k) { return k <= 0 || k >= cells_ ? 0.0 : w[k - 1]; };
  return (1.0 - s) * at(e) + s * at(e + 1);
}

double FluidLayer::deviation_slope(const std::vector<double>& w, double y) const {
  if (w.empty()) return 0.0;
  double s = 0.0;
  const int e = element(y, s);
  const auto at = [&](int k) { return k <= 0 || k >= cells_ ? 0.0 : w[k - 1]; };
  return (at(e + 1) - at(e)) / h_;
}

double FluidLayer::max_deviation_slope(const std::vector<double>& w) const {
  double m = 0.0, prev = 0.0;
  for (int k = 1; k <= cells_; ++k) {
    const double v = k < cells_ && !w.empty() ? w[k - 1] : 0.0;
    m = std::max(m, std::abs(v - prev) / h_);
    prev = v;
  }
  return m;
}

}  // namespace sheardiff
