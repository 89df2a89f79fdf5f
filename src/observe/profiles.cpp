#include "sheardiff/observe/profiles.hpp"

#include <algorithm>
#include <cmath>

#include "sheardiff/analysis/power_law.hpp"
#include "sheardiff/io/summary_keys.hpp"

namespace sheardiff {

double disc_area_between(double yc, double a, double y1, double y2) {
  // Area of the disc below height y: a^2 (pi/2 + u sqrt(1-u^2) + asin u), u = (y - yc)/a.
  const auto below = [&](double y) {
    const double u = std::clamp((y - yc) / a, -1.0, 1.0);
    return a * a * (0.5 * kPi + u * std::sqrt(1.0 - u * u) + std::asin(u));
  };
  return y2 > y1 ? below(y2) - below(y1) : 0.0;
}

double sphere_volume_between(double yc, double a, double y1, double y2) {
  // Volume of the cap below height y: pi h^2 (3 a - h) / 3, h = y - (yc - a) in [0, 2a].
  const auto below = [&](double y) {
    const double h = std::clamp(y - (yc - a), 0.0, 2.0 * a);
    return kPi * h * h * (3.0 * a - h) / 3.0;
  };
  return y2 > y1 ? below(y2) - below(y1) : 0.0;
}

void GapProfiles::grow(std::size_t bins) {
  if (w_.size() < bins)
    for (auto* vec : {&w_, &area_, &n_, &ux_, &ux2_, &uy2_}) vec->resize(bins, 0.0);
}

template <class D>
void GapProfiles::add(const ParticlesOf<D>& p, const std::vector<typename D::Body>& u, double yb,
                      double height, double section, double weight) {
  section_ = section;
  grow(static_cast<std::size_t>(std::ceil((height + 2.0) / bin_)));
  for (double& x : w_) x += weight;
  const auto bins = static_cast<long>(w_.size());
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    const double y = p.position[i].y() - yb, a = p.radius[i];
    const auto lo = static_cast<long>(std::floor((y - a) / bin_));
    const auto hi = static_cast<long>(std::floor((y + a) / bin_));
    for (long b = std::max(0L, lo); b <= hi && b < bins; ++b)
      area_[b] += weight * measure_between<D>(y, a, b * bin_, (b + 1) * bin_);
    const long c = static_cast<long>(std::floor(y / bin_));
    if (c < 0 || c >= bins) continue;
    const auto& v = u[i];
    n_[c] += weight;
    ux_[c] += weight * v.x();
    ux2_[c] += weight * v.x() * v.x();
    uy2_[c] += weight * v.y() * v.y();
  }
}

namespace {

// The force on j of the lubrication alone: the Lubrication law's block for the pair's geometry,
// exactly as the force balance assembled it (it depends on the geometry alone), times the pair
// velocity; zero where the law does not act.
template <class D>
typename D::Point lubrication_force_on_j(const Lubrication& law, const PairTermOf<D>& t,
                                         bool touching, const typename D::Body& ui,
                                         const typename D::Body& uj) {
  if (!law.acts(t.g, touching)) return D::Point::Zero();
  typename D::PairMatrix m = D::PairMatrix::Zero();
  typename D::PairVector f = D::PairVector::Zero();
  bool sliding = false;
  PairBlockOf<typename D::PairMatrix, typename D::PairVector> b{m, f, sliding};
  law.add_block(t.g, NoHistory{}, touching, 0.0, b);
  typename D::PairVector u;
  u << ui, uj + t.image_j;
  return -(m.template middleRows<D::space>(D::body) * u);
}

}  // namespace

template <class D>
void GapProfiles::add_stress(const DynamicsOf<D>& d, const std::vector<StageOf<D>>& stages,
                             double yb, double lz, double weight) {
  const auto bins = static_cast<long>(w_.size());
  if (bins == 0) return;
  const auto& lubrication = d.force_balance().lubrication();
  for (auto* vec : {&sxy_, &sp_}) vec->resize(w_.size(), 0.0);
  if (lubrication)
    for (auto* vec : {&sxy_lub_, &sp_lub_}) vec->resize(w_.size(), 0.0);
  const double volume = horizontal_area(d, lz) * bin_;
  for (const StageOf<D>& stage : stages)
    add_stage_stress(d, *stage.terms, *stage.velocities, yb, volume, weight * stage.weight);
}

template <class D>
void GapProfiles::add_stage_stress(const DynamicsOf<D>& d, const std::vector<PairTermOf<D>>& terms,
                                   const VelocitiesOf<D>& v, double yb, double volume,
                                   double weight) {
  const auto bins = static_cast<long>(w_.size());
  const auto& lubrication = d.force_balance().lubrication();
  const auto& pairs = d.neighbours().pairs();
  const auto& p = d.particles();
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& t = terms[k];
    if (!t.on) continue;
    const auto& pr = pairs[k];
    const double mid = p.position[pr.i].y() + 0.5 * t.g.r * t.g.n.y() - yb;
    // A pair with a wall disc may have its midpoint just outside the bins: the nearest one.
    const long c = std::clamp(static_cast<long>(std::floor(mid / bin_)), 0L, bins - 1);
    // The same pair stress as measure_stress (integrator/stress.cpp), binned.
    const auto fj = t.force(v.u[pr.i], v.u[pr.j]).template segment<D::space>(D::body).eval();
    const double l = pair_lever_arm(t.g, pr.history.touching);
    const auto ps = pair_stress<D>(t.g.n, fj, l);
    sxy_[c] += weight * ps.xy / volume;
    sp_[c] += weight * ps.pressure(D::space == 3) / volume;
    if (!lubrication) continue;
    const auto fl =
        lubrication_force_on_j<D>(*lubrication, t, pr.history.touching, v.u[pr.i], v.u[pr.j]);
    const auto pl = pair_stress<D>(t.g.n, fl, l);
    sxy_lub_[c] += weight * pl.xy / volume;
    sp_lub_[c] += weight * pl.pressure(D::space == 3) / volume;
  }
}

template void GapProfiles::add(const Particles&, const std::vector<Vec3>&, double, double, double,
                               double);
template void GapProfiles::add(const Particles3&, const std::vector<Vec6>&, double, double, double,
                               double);
template void GapProfiles::add_stress(const Dynamics&, const std::vector<StageOf<Dim2>>&, double,
                                      double, double);
template void GapProfiles::add_stress(const Dynamics3&, const std::vector<StageOf<Dim3>>&, double,
                                      double, double);

Eigen::MatrixXd GapProfiles::table() const {
  const auto nb = static_cast<Eigen::Index>(w_.size());
  Eigen::MatrixXd t(nb, 4);
  for (Eigen::Index b = 0; b < nb; ++b) {
    const double n = n_[b];
    const double ux = n > 0 ? ux_[b] / n : 0.0;
    t(b, 0) = (static_cast<double>(b) + 0.5) * bin_;
    t(b, 1) = w_[b] > 0 ? area_[b] / (w_[b] * section_ * bin_) : 0.0;
    t(b, 2) = ux;
    t(b, 3) = n > 0 ? ux2_[b] / n - ux * ux + uy2_[b] / n : 0.0;
  }
  return t;
}

void GapProfiles::to_summary(nlohmann::json& js, double gammadot, double height,
                             double exclusion) const {
  if (empty() || !(gammadot > 0.0)) return;
  const Eigen::MatrixXd t = table();
  std::vector<double> y, phi, ux, temp, yb, uxb;
  for (Eigen::Index b = 0; b < t.rows(); ++b) {
    y.push_back(t(b, 0));
    phi.push_back(t(b, 1));
    ux.push_back(t(b, 2) / gammadot);
    temp.push_back(t(b, 3) / (gammadot * gammadot));
    if (n_[b] > 0 && t(b, 0) >= exclusion && t(b, 0) <= height - exclusion)
      yb.push_back(t(b, 0)), uxb.push_back(t(b, 2) / gammadot);
  }
  js[summary_key::profile_y] = y;
  js[summary_key::profile_phi] = phi;
  js[summary_key::profile_u_x] = ux;  // in gammadot d (the imposed flow is y)
  js[summary_key::profile_T] = temp;  // in (gammadot d)^2
  js[summary_key::profile_bin] = bin_;
  if (yb.size() >= 3) js[summary_key::bulk_shear_rate_ratio] = fit_line(yb, uxb).slope;
  if (sxy_.size() == w_.size()) {
    std::vector<double> sxy(w_.size()), sp(w_.size());
    for (std::size_t b = 0; b < w_.size(); ++b) {
      sxy[b] = w_[b] > 0 ? sxy_[b] / w_[b] : 0.0;
      sp[b] = w_[b] > 0 ? sp_[b] / w_[b] : 0.0;
    }
    js[summary_key::profile_shear_stress] = sxy;  // sigma_xy of the pair forces, P
    js[summary_key::profile_pressure] = sp;  // minus the trace over 2 (discs) or 3 (spheres), P
  }
  if (sxy_lub_.size() == w_.size() && !lubrication_partial_) {
    std::vector<double> sxy(w_.size()), sp(w_.size());
    for (std::size_t b = 0; b < w_.size(); ++b) {
      sxy[b] = w_[b] > 0 ? sxy_lub_[b] / w_[b] : 0.0;
      sp[b] = w_[b] > 0 ? sp_lub_[b] / w_[b] : 0.0;
    }
    js[summary_key::profile_shear_stress_lubrication] = sxy;
    js[summary_key::profile_pressure_lubrication] = sp;
  }
}

template <class D>
void ProfilesObserverOf<D>::on_step(const StepView& v) {
  const Dynamics& d = v.dynamics;
  if (!d.walls() || !measuring_(d)) return;
  const double w = v.dt;
  // The bottom wall is fixed: its centre line is the profiles' origin for the whole run.
  const double yb = mean_height(d.particles(), d.walls()->bottom);
  w_ += w;
  h_ += w * d.height();
  profiles_.add(d.particles(), v.velocities.u, yb, d.height(), band_section(d), w);
  profiles_.add_stress(d, v.stages, yb, lz_, w);
}

template <class D>
void ProfilesObserverOf<D>::finish(const Dynamics& d, nlohmann::json& js, H5mdWriter* writer) {
  // Into summary.json (written whole or not at all), not into the trajectory: an HDF5 file
  // killed while its metadata is being changed can be left unreadable, and the end of a run
  // must be resumable at every instant (tests/cli/final_phase_kill.sh).
  (void)writer;
  if (w_ > 0.0) profiles_.to_summary(js, d.flow().gammadot, h_ / w_, exclusion_);
}

template class ProfilesObserverOf<Dim2>;
template class ProfilesObserverOf<Dim3>;

}  // namespace sheardiff
