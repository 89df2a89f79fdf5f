#include "sheardiff/integrator/stress.hpp"

#include <algorithm>

namespace sheardiff {

template <class D>
StressSample measure_stress(const DynamicsOf<D>& d, const VelocitiesOf<D>& v, double lz) {
  return measure_stress(d, d.force_balance().terms(), v, lz);
}

StressSample average(const StressSample& a, const StressSample& b) {
  StressSample m = a;
  m.sxx = 0.5 * (a.sxx + b.sxx);
  m.sxy = 0.5 * (a.sxy + b.sxy);
  m.syy = 0.5 * (a.syy + b.syy);
  m.szz = 0.5 * (a.szz + b.szz);
  m.max_overlap = std::max(a.max_overlap, b.max_overlap);
  m.mean_overlap = 0.5 * (a.mean_overlap + b.mean_overlap);
  m.top_wall_fx = 0.5 * (a.top_wall_fx + b.top_wall_fx);
  m.top_wall_fy = 0.5 * (a.top_wall_fy + b.top_wall_fy);
  m.bottom_wall_fx = 0.5 * (a.bottom_wall_fx + b.bottom_wall_fx);
  m.bottom_wall_fy = 0.5 * (a.bottom_wall_fy + b.bottom_wall_fy);
  return m;
}

template <class D>
StressSample measure_stress(const DynamicsOf<D>& d, const std::vector<PairTermOf<D>>& terms,
                            const VelocitiesOf<D>& v, double lz) {
  StressSample s;
  const auto& pairs = d.neighbours().pairs();
  const auto& p = d.particles();
  double overlap_sum = 0.0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& t = terms[k];
    if (!t.on) continue;
    const auto& pr = pairs[k];
    const auto fj = t.force(v.u[pr.i], v.u[pr.j]).template segment<D::space>(D::body).eval();
    const bool contact = pr.history.touching;
    const auto ps = pair_stress<D>(t.g.n, fj, pair_lever_arm(t.g, contact));
    s.sxx += ps.xx;
    s.syy += ps.yy;
    s.sxy += ps.xy;
    s.szz += ps.zz;
    if (contact) {
      ++s.contacts;
      const double ov = std::max(t.g.overlap(), 0.0);
      s.max_overlap = std::max(s.max_overlap, ov);
      overlap_sum += ov;
    }
    switch (p.motion[pr.j]) {
      case Motion::FloatingWall:
      case Motion::DrivenWall:
        s.top_wall_fx += fj.x();
        s.top_wall_fy += fj.y();
        break;
      case Motion::FixedWall:
        s.bottom_wall_fx += fj.x();
        s.bottom_wall_fy += fj.y();
        break;
      case Motion::Mobile:
        break;
    }
  }
  const double area = horizontal_area(d, lz) * d.height();
  s.sxx /= area;
  s.syy /= area;
  s.sxy /= area;
  s.szz /= area;
  s.spheres = D::space == 3;
  s.mean_overlap = s.contacts ? overlap_sum / s.contacts : 0.0;
  return s;
}

template StressSample measure_stress(const Dynamics&, const Velocities&, double);
template StressSample measure_stress(const Dynamics3&, const VelocitiesOf<Dim3>&, double);
template StressSample measure_stress(const Dynamics&, const std::vector<PairTerm>&,
                                     const Velocities&, double);
template StressSample measure_stress(const Dynamics3&, const std::vector<PairTermOf<Dim3>>&,
                                     const VelocitiesOf<Dim3>&, double);

template <class D>
double normal_load_between(const DynamicsOf<D>& d, const std::vector<StageOf<D>>& stages, double y1,
                           double y2, double lz) {
  if (!(y2 > y1)) return 0.0;
  const auto& pairs = d.neighbours().pairs();
  const auto& p = d.particles();
  double load = 0.0;
  for (const StageOf<D>& stage : stages)
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const auto& t = (*stage.terms)[k];
      if (!t.on) continue;
      const auto& pr = pairs[k];
      const double mid = p.position[pr.i].y() + 0.5 * t.g.r * t.g.n.y();
      if (mid < y1 || mid >= y2) continue;
      // Lever arm r (not the stress convention's s for open pairs): sum of dy_ij f_y over the
      // band's pairs is exactly the band's mean of the force across a horizontal line.
      const auto& u = stage.velocities->u;
      load += stage.weight * t.g.r * t.g.n.y() * t.force(u[pr.i], u[pr.j])(D::body + 1);
    }
  return load / (horizontal_area(d, lz) * (y2 - y1));
}

template double normal_load_between(const Dynamics&, const std::vector<StageOf<Dim2>>&, double,
                                    double, double);
template double normal_load_between(const Dynamics3&, const std::vector<StageOf<Dim3>>&, double,
                                    double, double);

namespace {

template <class D>
ContactNetwork contact_network_of(const DynamicsOf<D>& d) {
  ContactNetwork c;
  c.components = D::space == 2 ? 1 : 3;
  const auto& p = d.particles();
  const FrictionalContact& law = d.force_balance().contact();
  for (const auto& pr : d.neighbours().pairs()) {
    if (!pr.history.touching) continue;
    // Geometry of now, not of the last solve: the frame shows the positions of now.
    const auto g =
        PairGeometryOf<D>::make(pair_separation(p, d.box(), pr), p.radius[pr.i], p.radius[pr.j]);
    // A pair the last move opened is touching until the next contact update, but not in contact
    // at these positions: listed, it showed a normal force of exactly 0.
    if (!(g.overlap() > 0.0)) continue;
    c.pairs.push_back({pr.i, pr.j});
    c.normal_force.push_back(law.kn_of(g) * g.overlap());
    // The spring force on j, -kt xi: along z x n for discs; for spheres the vector in the plane
    // normal to n as the last cap left it (FrictionalContact::spring_force_3d).
    if constexpr (D::space == 2) {
      c.tangential_force.push_back(-law.kt_of(g) * pr.history.contact.xi);
    } else {
      const Space3 ft = -law.kt_of(g) * pr.history.contact.xi;
      c.tangential_force.insert(c.tangential_force.end(), {ft.x(), ft.y(), ft.z()});
    }
    c.sliding.push_back(pr.history.contact.sliding ? 1 : 0);
  }
  return c;
}

}  // namespace

ContactNetwork contact_network(const Dynamics& d) {
  return contact_network_of(d);
}
ContactNetwork contact_network(const Dynamics3& d) {
  return contact_network_of(d);
}

}  // namespace sheardiff
