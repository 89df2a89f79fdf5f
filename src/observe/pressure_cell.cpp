#include "sheardiff/observe/pressure_cell.hpp"

#include <algorithm>
#include <cmath>

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

namespace {
double mean_y(const Particles& p, const std::vector<int>& ids) {
  double s = 0.0;
  for (int k : ids) s += p.position[k].y();
  return s / static_cast<double>(ids.size());
}
}  // namespace

PressureCellObserver::PressureCellObserver(const Config& cfg)
    : steady_cfg_(cfg.steady),
      exclusion_(cfg.observables.wall_exclusion),
      bin_(cfg.observables.profile_bin),
      pressure_(1.0),
      lz_(cfg.flow.lz),
      run_strain_(cfg.run.strain) {}

double PressureCellObserver::bulk_phi(const Dynamics& d, double exclusion) {
  const Particles& p = d.particles();
  const double yb = mean_y(p, d.walls()->bottom), yt = mean_y(p, d.walls()->top);
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
  if (steady()) return;
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
  accumulate_profiles(v);
}

void PressureCellObserver::accumulate_profiles(const StepView& v) {
  const Dynamics& d = v.dynamics;
  const Particles& p = d.particles();
  const double yb = d.flow().y0;
  const std::size_t need = static_cast<std::size_t>(std::ceil((d.height() + 2.0) / bin_));
  if (prof_w_.size() < need) {
    for (auto* vec : {&prof_w_, &prof_area_, &prof_n_, &prof_ux_, &prof_ux2_, &prof_uy2_})
      vec->resize(need, 0.0);
  }
  const double w = v.dt;
  for (double& x : prof_w_) x += w;
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    const double y = p.position[i].y() - yb, a = p.radius[i];
    const auto lo = static_cast<long>(std::floor((y - a) / bin_));
    const auto hi = static_cast<long>(std::floor((y + a) / bin_));
    for (long b = std::max(0L, lo); b <= hi && b < static_cast<long>(need); ++b)
      prof_area_[b] += w * disc_area_between(y, a, b * bin_, (b + 1) * bin_);
    const long c = static_cast<long>(std::floor(y / bin_));
    if (c < 0 || c >= static_cast<long>(need)) continue;
    const Vec3& u = v.velocities.u[i];
    prof_n_[c] += w;
    prof_ux_[c] += w * u.x();
    prof_ux2_[c] += w * u.x() * u.x();
    prof_uy2_[c] += w * u.y() * u.y();
  }
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
  if (writer && !prof_w_.empty()) {
    const auto nb = static_cast<Eigen::Index>(prof_w_.size());
    Eigen::MatrixXd t(nb, 4);
    for (Eigen::Index b = 0; b < nb; ++b) {
      const double n = prof_n_[b];
      const double ux = n > 0 ? prof_ux_[b] / n : 0.0;
      t(b, 0) = (b + 0.5) * bin_;
      t(b, 1) = prof_area_[b] / (prof_w_[b] * d.box().lx * bin_);
      t(b, 2) = ux;
      t(b, 3) = n > 0 ? prof_ux2_[b] / n - ux * ux + prof_uy2_[b] / n : 0.0;
    }
    writer->write_table("profiles", {"y", "phi", "u_x", "T"},
                        {"d", "1", "P d eta-1", "P+2 d+2 eta-2"}, t);
  }
}

}  // namespace sheardiff
