#pragma once
#include <vector>

#include "sheardiff/analysis/stationarity.hpp"
#include "sheardiff/analysis/uncertainty.hpp"
#include "sheardiff/config.hpp"
#include "sheardiff/observe/observer.hpp"
#include "sheardiff/observe/profiles.hpp"

namespace sheardiff {

// The measured window's signals, sampled frame by frame from the detection of steady state on,
// in a BinnedSeries of this many signals, in this order: mu = (mu_top + mu_bottom) / 2 and
// mu_top - mu_bottom are formed frame by frame; net_drag_y is the walls' load difference over
// P Lx lz, bulk_load the bulk's normal load over P. Bounded bins keep a long run's state small.
struct CellSignal {
  enum : std::size_t { h, phi, mu_top, mu_bottom, mu, mu_difference, net_drag_y, bulk_load, count };
};
constexpr std::size_t kCellWindowBins = 2048;
void add_cell_sample(BinnedSeries& window, double strain, double h, double phi, double mu_top,
                     double mu_bottom, double net_drag_y, double bulk_load);
// The window's series of frames in [from, to] (what the run's observer took, for `analyse`);
// an empty phi, net_drag_y or bulk_load vector leaves that signal without values.
BinnedSeries cell_window(const std::vector<double>& strain, const std::vector<double>& h,
                         const std::vector<double>& phi, const std::vector<double>& mu_top,
                         const std::vector<double>& mu_bottom,
                         const std::vector<double>& net_drag_y,
                         const std::vector<double>& bulk_load, double from, double to);

// Statistical errors of the steady window's H, phi, mu, mu_top, mu_bottom (batch means over
// blocks of `block` strain from `from` to `to`): *_err keys into summary.
void add_steady_errors(nlohmann::json& js, const BinnedSeries& window, double from, double to,
                       double block);

// Whether the window [from, to] of a pressure cell was stationary: the net y drag on the discs
// (the walls' load difference over P Lx lz) and mu_top - mu_bottom zero, and H without a trend,
// each within steady.drift_z standard errors; the bulk's normal load P within
// steady.bulk_load_tolerance. Blocks as in add_steady_errors.
StationarityVerdict pressure_cell_stationarity(const SteadyStateParams& cfg,
                                               const BinnedSeries& window, double from, double to,
                                               double block);
// Its signals into summary.json: stationary, not_stationary (the failed signals), and each
// signal's value and error (net_drag_y, mu_top_minus_bottom, H_change, bulk_normal_load).
void add_stationarity(nlohmann::json& js, const StationarityVerdict& v);
// The block means the errors and the verdict are formed from (window_blocks in summary.json),
// so that a reader can see a drift the verdict weighed, or one it let pass, without the
// trajectory. Blocks as in add_steady_errors; nothing for a window of fewer than 8 frames.
void add_window_blocks(nlohmann::json& js, const BinnedSeries& window, double from, double to,
                       double block);

// Observables of the pressure-imposed plane shear cell (docs/model.md section 9): gap H, bulk phi,
// mu = tau / P and the measured pressure from the wall forces, steady-state detection from the
// drift of H and mu (its profiles across the gap: ProfilesObserver, over the steady window).
template <class D>
class PressureCellObserverOf final : public ObserverOf<D> {
 public:
  using typename ObserverOf<D>::Dynamics;
  using typename ObserverOf<D>::StepView;

  explicit PressureCellObserverOf(const Config& cfg);
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
    serialize_window(a);
  }

  bool steady() const { return steady_at_ >= 0.0; }
  // The measured window's samples so far (CellSignal).
  const BinnedSeries& window() const { return window_; }
  double steady_strain() const { return steady_from_; }
  // Bulk area (discs) or volume (spheres) fraction of the current configuration.
  static double bulk_phi(const Dynamics& d, double exclusion);

 private:
  SteadyStateParams steady_cfg_;
  double exclusion_, pressure_, lz_, run_strain_, error_block_;
  std::vector<double> hist_strain_, hist_h_, hist_mu_;
  double steady_at_ = -1.0;    // strain at which steadiness was detected
  double steady_from_ = -1.0;  // start of the no-drift window
  // Steady-window time averages.
  double w_ = 0, h_ = 0, phi_ = 0, phi2_ = 0, mu_top_ = 0, mu_bottom_ = 0, p_meas_ = 0;
  double max_p_err_ = 0;
  long free_fall_steps_ = 0;
  // The steady window's frame samples (CellSignal), for the error bars and the stationarity test.
  BinnedSeries window_{CellSignal::count, kCellWindowBins};
  void serialize_window(Archive& a);
};

using PressureCellObserver = PressureCellObserverOf<Dim2>;

}  // namespace sheardiff
