#pragma once
#include "sheardiff/core/contact_network.hpp"
#include "sheardiff/integrator/dynamics.hpp"

namespace sheardiff {

// Pair stress and contact statistics of one configuration (docs/model.md section 9):
// sigma = -(1 / (area lz)) sum over pairs of sym(l n (x) F_j), l = r in contact, s otherwise,
// F_j the pair force on j. Tension positive: pressure = -(sigma_xx + sigma_yy) / 2 of discs,
// -(sigma_xx + sigma_yy + sigma_zz) / 3 of spheres.
struct StressSample {
  double sxx = 0, sxy = 0, syy = 0;
  double szz = 0;  // spheres only
  bool spheres = false;
  double pressure() const { return spheres ? -(sxx + syy + szz) / 3.0 : -0.5 * (sxx + syy); }
  double shear_stress() const { return sxy; }
  int contacts = 0;
  double max_overlap = 0.0;
  double mean_overlap = 0.0;
  double top_wall_fx = 0.0;  // force of the suspension on the top wall (walls only)
  double top_wall_fy = 0.0;
  double bottom_wall_fx = 0.0;
  double bottom_wall_fy = 0.0;
};

// One pair's share of sigma times the volume: -sym(l n (x) F_j), F_j the pair force on j along
// the lever arm l n (pair_lever_arm). Shared by the cell's stress and the gap profiles' binned one,
// so that the two sum the same quantity.
struct PairStress {
  double xx = 0, yy = 0, zz = 0, xy = 0;  // zz: spheres only
  // The pair's share of the trace pressure: two normal stresses of discs, three of spheres.
  double pressure(bool spheres) const { return spheres ? -(xx + yy + zz) / 3.0 : -0.5 * (xx + yy); }
};
template <class D>
PairStress pair_stress(const typename D::Point& n, const typename D::Point& fj, double l) {
  PairStress s;
  s.xx = -l * n.x() * fj.x();
  s.yy = -l * n.y() * fj.y();
  s.xy = -0.5 * l * (n.x() * fj.y() + n.y() * fj.x());
  if constexpr (D::space == 3) s.zz = -l * n.z() * fj.z();
  return s;
}
// The lever arm of a pair's stress: the centre distance r of a pair in contact, the surface gap
// s of an open one (docs/model.md section 9).
template <class Geometry>
double pair_lever_arm(const Geometry& g, bool touching) {
  return touching ? g.r : g.s;
}

// One solve of a step: its pair terms, the velocities it gave and its share of the step's motion.
// A step moves the particles with the weighted sum of its stages' velocities (one stage, weight
// 1, for Euler and implicit springs; predictor and corrector, 1/2 each, for Heun), so a pair sum
// over forces is that weighted sum of each stage's own terms times its own velocities.
template <class D>
struct StageOf {
  const std::vector<PairTermOf<D>>* terms;
  const VelocitiesOf<D>* velocities;
  double weight;
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
// dilates from its middle carries more than P there though its net drag is zero. Summed over
// the step's stages.
template <class D>
double normal_load_between(const DynamicsOf<D>& d, const std::vector<StageOf<D>>& stages, double y1,
                           double y2, double lz);

// The area a force across a horizontal plane is spread over: lx lz, lz the monolayer's
// thickness for discs and the periodic cell's depth for spheres.
template <class D>
double horizontal_area(const DynamicsOf<D>& d, double lz) {
  if constexpr (D::space == 3) lz = d.box().lz;
  return d.box().lx * lz;
}
// What a horizontal band's volume fraction is over, per unit height: lx for discs (an area
// fraction), lx lz for spheres.
template <class D>
double band_section(const DynamicsOf<D>& d) {
  if constexpr (D::space == 3) return d.box().lx * d.box().lz;
  return d.box().lx;
}
// A particle's own measure: a disc's area, a sphere's volume.
template <class D>
double particle_measure(double a) {
  if constexpr (D::space == 3) return 4.0 / 3.0 * kPi * a * a * a;
  return kPi * a * a;
}

// Weighted mean of two samples (stresses, wall forces, overlaps); the contact count of `a`.
StressSample average(const StressSample& a, const StressSample& b);

// The contacts open at the current configuration with their spring forces (ContactNetwork).
ContactNetwork contact_network(const Dynamics& d);
ContactNetwork contact_network(const Dynamics3& d);

}  // namespace sheardiff
