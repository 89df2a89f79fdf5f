#pragma once
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/observe/observer.hpp"

namespace sheardiff {

// Area of the disc (centre height yc, radius a) lying between heights y1 < y2.
double disc_area_between(double yc, double a, double y1, double y2);

// phi(y), u_x(y) and the fluctuation temperature T(y) = <u'.u'> of the mobile discs across the
// gap, in bins of `bin` d measured from the bottom wall's centre line, averaged with any weight
// (dt during a run, 1 per frame when recomputed from a trajectory).
class GapProfiles {
 public:
  explicit GapProfiles(double bin) : bin_(bin) {}
  void add(const Particles& p, const std::vector<Vec3>& u, double y_bottom, double height,
           double lx, double weight);
  bool empty() const { return w_.empty(); }
  // Rows = bins; columns y (bin centre), phi, u_x, T.
  Eigen::MatrixXd table() const;
  // The table into summary: profile_{y, phi, u_x, T} with velocities over gammadot, and the
  // shear rate of the bulk (a line fit of u_x over the bins at least `exclusion` from both
  // walls) over the imposed gammadot = V / H.
  void to_summary(nlohmann::json& js, double gammadot, double height, double exclusion) const;
  void serialize(Archive& a) {
    a.io(lx_);
    for (auto* v : {&w_, &area_, &n_, &ux_, &ux2_, &uy2_}) a.io(*v);
  }

 private:
  double bin_, lx_ = 1.0;
  std::vector<double> w_, area_, n_, ux_, ux2_, uy2_;
};

// Statistical errors of the steady window's H, phi, mu, mu_top, mu_bottom from frame samples
// (batch means over blocks of `block` strain from `from` to `to`): *_err keys into summary.
void add_steady_errors(nlohmann::json& js, const std::vector<double>& strain,
                       const std::vector<double>& h, const std::vector<double>& phi,
                       const std::vector<double>& mu_top, const std::vector<double>& mu_bottom,
                       double from, double to, double block);

// Observables of the pressure-imposed plane shear cell (docs/model.md section 9): gap H, bulk phi,
// mu = tau / P and the measured pressure from the wall forces, steady-state detection from the
// drift of H and mu, and phi(y), u_x(y), T(y) profiles averaged over the steady window.
class PressureCellObserver final : public Observer {
 public:
  explicit PressureCellObserver(const Config& cfg);
  std::vector<std::string> frame_names() const override;
  std::vector<std::string> frame_units() const override;
  void on_frame(const StepView& v, std::vector<double>& values) override;
  void on_step(const StepView& v) override;
  bool done(const Dynamics& d) const override;
  double planned_end_strain() const override;
  void finish(const Dynamics& d, nlohmann::json& summary, H5mdWriter* writer) override;

  void serialize(Archive& a) override {
    a.tag("pressure_cell");
    a.io(hist_strain_), a.io(hist_h_), a.io(hist_mu_);
    for (double* x : {&steady_at_, &steady_from_, &w_, &h_, &phi_, &phi2_, &mu_top_, &mu_bottom_,
                      &p_meas_, &max_p_err_})
      a.io(*x);
    a.io(free_fall_steps_);
    profiles_.serialize(a);
    for (auto* v : {&s_strain_, &s_h_, &s_phi_, &s_mu_top_, &s_mu_bottom_}) a.io(*v);
  }

  bool steady() const { return steady_at_ >= 0.0; }
  double steady_strain() const { return steady_from_; }
  // Bulk area fraction of the current configuration.
  static double bulk_phi(const Dynamics& d, double exclusion);

 private:
  Config::Steady steady_cfg_;
  double exclusion_, pressure_, lz_, run_strain_, error_block_;
  std::vector<double> hist_strain_, hist_h_, hist_mu_;
  double steady_at_ = -1.0;    // strain at which steadiness was detected
  double steady_from_ = -1.0;  // start of the no-drift window
  // Steady-window time averages.
  double w_ = 0, h_ = 0, phi_ = 0, phi2_ = 0, mu_top_ = 0, mu_bottom_ = 0, p_meas_ = 0;
  double max_p_err_ = 0;
  long free_fall_steps_ = 0;
  GapProfiles profiles_;
  // Frame samples of the steady window, for the error bars.
  std::vector<double> s_strain_, s_h_, s_phi_, s_mu_top_, s_mu_bottom_;
};

}  // namespace sheardiff
