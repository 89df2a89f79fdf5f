#include "sheardiff/observe/pressure_cell.hpp"

#include <algorithm>
#include <cmath>

#include "sheardiff/analysis/power_law.hpp"
#include "sheardiff/analysis/uncertainty.hpp"
#include "sheardiff/io/h5md.hpp"

namespace sheardiff {

double disc_area_between(double yc, double a, double y1, double y2) {
  // Area of the disc below height y: a^2 (pi/2 + u sqrt(1-u^2) + asin u), u = (y - yc)/a.
  const auto below = [&](double y) {
    const double u = std::clamp((y - yc) / a, -1.0, 1.0);
    return a * a * (0.5 * kPi + u * std::sqrt(1.0 - u * u) + std::asin(u));
  };
  return y2 > y1 ? below(y2) - below(y1) : 0.0;
}

void GapProfiles::add(const Particles& p, const std::vector<Vec3>& u, double yb, double height,
                      double lx, double weight) {
  lx_ = lx;
  const std::size_t need = static_cast<std::size_t>(std::ceil((height + 2.0) / bin_));
  if (w_.size() < need)
    for (auto* vec : {&w_, &area_, &n_, &ux_, &ux2_, &uy2_}) vec->resize(need, 0.0);
  for (double& x : w_) x += weight;
  const auto bins = static_cast<long>(w_.size());
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    const double y = p.position[i].y() - yb, a = p.radius[i];
    const auto lo = static_cast<long>(std::floor((y - a) / bin_));
    const auto hi = static_cast<long>(std::floor((y + a) / bin_));
    for (long b = std::max(0L, lo); b <= hi && b < bins; ++b)
      area_[b] += weight * disc_area_between(y, a, b * bin_, (b + 1) * bin_);
    const long c = static_cast<long>(std::floor(y / bin_));
    if (c < 0 || c >= bins) continue;
    const Vec3& v = u[i];
    n_[c] += weight;
    ux_[c] += weight * v.x();
    ux2_[c] += weight * v.x() * v.x();
    uy2_[c] += weight * v.y() * v.y();
  }
}

Eigen::MatrixXd GapProfiles::table() const {
  const auto nb = static_cast<Eigen::Index>(w_.size());
  Eigen::MatrixXd t(nb, 4);
  for (Eigen::Index b = 0; b < nb; ++b) {
    const double n = n_[b];
    const double ux = n > 0 ? ux_[b] / n : 0.0;
    t(b, 0) = (static_cast<double>(b) + 0.5) * bin_;
    t(b, 1) = w_[b] > 0 ? area_[b] / (w_[b] * lx_ * bin_) : 0.0;
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
  js["profile_y"] = y;
  js["profile_phi"] = phi;
  js["profile_u_x"] = ux;  // in gammadot d (the imposed flow is y)
  js["profile_T"] = temp;  // in (gammadot d)^2
  js["profile_bin"] = bin_;
  if (yb.size() >= 3) js["bulk_shear_rate_ratio"] = fit_line(yb, uxb).slope;
}

void add_steady_errors(nlohmann::json& js, const std::vector<double>& strain,
                       const std::vector<double>& h, const std::vector<double>& phi,
                       const std::vector<double>& mu_top, const std::vector<double>& mu_bottom,
                       double from, double to, double block) {
  if (!(to > from) || strain.size() < 8) return;
  const long blocks = std::max(4L, static_cast<long>((to - from) / block));
  std::vector<double> mu(mu_top.size());
  for (std::size_t k = 0; k < mu.size(); ++k) mu[k] = 0.5 * (mu_top[k] + mu_bottom[k]);
  const auto err = [&](const std::vector<double>& x) {
    const double e = batch_means(strain, x, from, to, blocks).err;
    return std::isfinite(e) ? nlohmann::json(e) : nlohmann::json(nullptr);
  };
  js["H_err"] = err(h);
  js["phi_err"] = err(phi);
  js["mu_err"] = err(mu);
  js["mu_top_err"] = err(mu_top);
  js["mu_bottom_err"] = err(mu_bottom);
}

PressureCellObserver::PressureCellObserver(const Config& cfg)
    : steady_cfg_(cfg.steady),
      exclusion_(cfg.observables.wall_exclusion),
      pressure_(1.0),
      lz_(cfg.flow.lz),
      run_strain_(cfg.run.strain),
      error_block_(cfg.analysis.error_block),
      profiles_(cfg.observables.profile_bin) {}

double PressureCellObserver::bulk_phi(const Dynamics& d, double exclusion) {
  const Particles& p = d.particles();
  const double yb = mean_height(p, d.walls()->bottom), yt = mean_height(p, d.walls()->top);
  double y1 = yb + exclusion, y2 = yt - exclusion;
  if (y2 - y1 < 1.0) y1 = yb, y2 = yt;  // a thin cell has no bulk: use the whole gap
  double area = 0.0;
  for (std::size_t i = 0; i < p.n_mobile; ++i)
    area += disc_area_between(p.position[i].y(), p.radius[i], y1, y2);
  return area / (d.box().lx * (y2 - y1));
}

std::vector<std::string> PressureCellObserver::frame_names() const {
  return {"H", "phi", "mu_top", "mu_bottom", "pressure_measured", "wall_velocity_y"};
}

std::vector<std::string> PressureCellObserver::frame_units() const {
  return {"d", "1", "1", "1", "P", "P d eta-1"};
}

void PressureCellObserver::on_frame(const StepView& v, std::vector<double>& values) {
  const Dynamics& d = v.dynamics;
  const double a = d.box().lx * lz_;
  const double mu_top = -v.stress.top_wall_fx / a / pressure_;
  const double h = d.height();
  values.insert(values.end(),
                {h, bulk_phi(d, exclusion_), mu_top, v.stress.bottom_wall_fx / a / pressure_,
                 v.stress.top_wall_fy / a, v.velocities.wall_v});
  if (steady()) {
    s_strain_.push_back(d.strain());
    s_h_.push_back(h);
    s_phi_.push_back(values[values.size() - 5]);
    s_mu_top_.push_back(mu_top);
    s_mu_bottom_.push_back(values[values.size() - 3]);
    return;
  }
  hist_strain_.push_back(d.strain());
  hist_h_.push_back(h);
  hist_mu_.push_back(mu_top);
  const double now = d.strain();
  if (now - hist_strain_.front() < steady_cfg_.window) return;
  // Means of H and mu over the two halves of the last window.
  const double start = now - steady_cfg_.window, mid = now - 0.5 * steady_cfg_.window;
  double h1 = 0, h2 = 0, m1 = 0, m2 = 0;
  int n1 = 0, n2 = 0;
  for (std::size_t k = 0; k < hist_strain_.size(); ++k) {
    if (hist_strain_[k] < start) continue;
    if (hist_strain_[k] < mid)
      h1 += hist_h_[k], m1 += hist_mu_[k], ++n1;
    else
      h2 += hist_h_[k], m2 += hist_mu_[k], ++n2;
  }
  if (n1 < 2 || n2 < 2) return;
  h1 /= n1, h2 /= n2, m1 /= n1, m2 /= n2;
  if (std::abs(h2 - h1) <= steady_cfg_.h_tolerance * 0.5 * (h1 + h2) &&
      std::abs(m2 - m1) <= steady_cfg_.mu_tolerance) {
    steady_at_ = now;
    steady_from_ = start;
  }
}

void PressureCellObserver::on_step(const StepView& v) {
  const Dynamics& d = v.dynamics;
  const double a = d.box().lx * lz_;
  if (v.velocities.wall_free_fall)
    ++free_fall_steps_;
  else
    max_p_err_ = std::max(max_p_err_, std::abs(v.stress.top_wall_fy / a - pressure_) / pressure_);
  if (!steady()) return;
  const double w = v.dt;
  const double phi = bulk_phi(d, exclusion_);
  w_ += w;
  h_ += w * d.height();
  phi_ += w * phi;
  phi2_ += w * phi * phi;
  mu_top_ += w * (-v.stress.top_wall_fx / a / pressure_);
  mu_bottom_ += w * (v.stress.bottom_wall_fx / a / pressure_);
  p_meas_ += w * v.stress.top_wall_fy / a;
  profiles_.add(d.particles(), v.velocities.u, d.flow().y0, d.height(), d.box().lx, w);
}

double PressureCellObserver::planned_end_strain() const {
  if (steady() && steady_cfg_.measure_strain > 0.0) return steady_at_ + steady_cfg_.measure_strain;
  return Observer::planned_end_strain();
}

bool PressureCellObserver::done(const Dynamics& d) const {
  return steady() && steady_cfg_.measure_strain > 0.0 &&
         d.strain() >= steady_at_ + steady_cfg_.measure_strain;
}

void PressureCellObserver::finish(const Dynamics& d, nlohmann::json& js, H5mdWriter* writer) {
  js["steady"] = steady();
  js["steady_strain"] = steady() ? nlohmann::json(steady_from_) : nlohmann::json(nullptr);
  js["steady_detected_at"] = steady() ? nlohmann::json(steady_at_) : nlohmann::json(nullptr);
  // Over every step where the packing holds the wall (free-fall steps are counted apart).
  js["pressure_max_relative_error"] = max_p_err_;
  js["wall_free_fall_steps"] = free_fall_steps_;
  if (!steady() || w_ <= 0.0) {
    js["steady"] = false;
    js["note"] = steady()
                     ? "steady state detected at the last step: nothing measured after it; "
                       "run longer (run.strain)"
                     : "steady state not reached: H or mu still drift; run longer (run.strain)";
    js["H"] = d.height();
    js["phi"] = bulk_phi(d, exclusion_);
    return;
  }
  const double phi = phi_ / w_;
  js["H"] = h_ / w_;
  js["phi"] = phi;
  js["phi_std"] = std::sqrt(std::max(0.0, phi2_ / w_ - phi * phi));
  js["mu"] = 0.5 * (mu_top_ + mu_bottom_) / w_;
  js["mu_top"] = mu_top_ / w_;
  js["mu_bottom"] = mu_bottom_ / w_;
  js["pressure_measured"] = p_meas_ / w_;
  js["measured_strain"] = d.strain() - steady_at_;
  add_steady_errors(js, s_strain_, s_h_, s_phi_, s_mu_top_, s_mu_bottom_, steady_at_, d.strain(),
                    error_block_);
  // Into summary.json (written whole or not at all), not into the trajectory: an HDF5 file
  // killed while its metadata is being changed can be left unreadable, and the end of a run
  // must be resumable at every instant (tests/cli/final_phase_kill.sh).
  profiles_.to_summary(js, d.flow().gammadot, h_ / w_, exclusion_);
  (void)writer;
}

}  // namespace sheardiff
