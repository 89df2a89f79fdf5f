#pragma once
#include "sheardiff/core/contact_network.hpp"
#include "sheardiff/integrator/dynamics.hpp"

namespace sheardiff {

// Pair stress and contact statistics of one configuration (docs/model.md section 9):
// sigma = -(1 / (area lz)) sum over pairs of sym(l n (x) F_j), l = r in contact, s otherwise,
// F_j the pair force on j. Tension positive: pressure = -(sigma_xx + sigma_yy) / 2.
struct StressSample {
  double sxx = 0, sxy = 0, syy = 0;
  double pressure() const { return -0.5 * (sxx + syy); }
  double shear_stress() const { return sxy; }
  int contacts = 0;
  double max_overlap = 0.0;
  double mean_overlap = 0.0;
  double top_wall_fx = 0.0;  // force of the suspension on the top wall (walls only)
  double top_wall_fy = 0.0;
  double bottom_wall_fx = 0.0;
  double bottom_wall_fy = 0.0;
};

// Discs or spheres; lz is a monolayer's thickness (spheres: the cell's own lz is used).
template <class D>
StressSample measure_stress(const DynamicsOf<D>& d, const VelocitiesOf<D>& v, double lz);
// The same with pair terms other than the last solve's (a stage of a multi-stage integrator).
template <class D>
StressSample measure_stress(const DynamicsOf<D>& d, const std::vector<PairTermOf<D>>& terms,
                            const VelocitiesOf<D>& v, double lz);
// The normal load a horizontal band of the packing carries, in pressure units: sum over the
// pairs whose midpoints lie between heights y1 < y2 of (y_j - y_i) f_y on j, over the band's
// area (-sigma_yy with the lever arm r for every pair). Where nothing moves on average in y,
// momentum balance makes it equal the load on the walls at every height; a packing that
// dilates from its middle carries more than P there though its net drag is zero.
double normal_load_between(const Dynamics& d, const Velocities& v, double y1, double y2, double lz);
// Weighted mean of two samples (stresses, wall forces, overlaps); the contact count of `a`.
StressSample average(const StressSample& a, const StressSample& b);

// The contacts open at the current configuration with their spring forces (ContactNetwork).
ContactNetwork contact_network(const Dynamics& d);

}  // namespace sheardiff
