#pragma once
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sheardiff/analysis/correlator.hpp"
#include "sheardiff/analysis/time_series.hpp"
#include "sheardiff/analysis/uncertainty.hpp"
#include "sheardiff/core/archive.hpp"

namespace sheardiff {

struct DiffusionSettings {
  double window_lo = 8.0, window_hi = 15.0;  // MSD fit window, strain
  double vacf_max_lag = 2.0;                 // strain; Psi gammadot <= ~0.2 for J <= 0.1
  double error_block = 3.0;                  // strain: time blocks of the error bars
  std::vector<double> velocity_intervals;    // strain: displacement velocities also reported
  double coarse_strain = 0.2;                // strain: spacing of the samples D comes from
                                             // (config: min(0.2, window_hi / 75))
};

// Self-diffusion in the gradient direction (seed paper section 3, docs/model.md section 9) from
// samples uniformly spaced by sample_strain: y (unwrapped, in d) and vy (v_y / gammadot, in d
// per unit strain) of every mobile disc. Times are strains, so D comes out in gammadot d^2, dv
// in gammadot d and Psi in 1/gammadot.
struct DiffusionReport {
  MsdResult msd;         // every origin, lags on the correlator's multiple-tau grid
  MsdResult msd_coarse;  // every origin on the samples coarse_strain apart: what D fits
  Autocorrelation vacf;
  DiffusionFit fit;         // D: OLS over the fit window of msd_coarse, regression error
  MsdSlopeError d_error;    // the error bar of D from the run's own time blocks
  PersistenceEstimate vel;  // dv, Psi (every definition) and their jackknife errors
  Persistence persistence;  // = vel.p
  double dv = 0.0;
  // The same analysis restricted to discs in the bulk (away from the walls) at the reference
  // time, when a bulk mask was given: bulk_fraction of the (disc, time) samples.
  bool has_bulk = false;
  MsdResult msd_bulk;
  DiffusionFit fit_bulk;
  PersistenceEstimate vel_bulk;
  double bulk_fraction = 0.0;
  // The MSD of the x displacement relative to the imposed flow, when it was sampled.
  bool has_x = false;
  MsdResult msd_x;
  DiffusionFit fit_x;
  // dv and Psi of the displacement velocity (y(t + Delta) - y(t)) / Delta, per interval.
  struct IntervalVelocity {
    double interval = 0.0;       // Delta, strain, as rounded to the grid
    double sample_strain = 0.0;  // spacing of its samples
    PersistenceEstimate vel;
  };
  std::vector<IntervalVelocity> intervals;
  double error_block = 0.0;  // strain, as used
  double step_length = 0.0;  // dv Psi
  double consistency = 0.0;  // D / (dv^2 Psi), 1 if the VACF integral carries the diffusion
  double window_lo = 0.0, window_hi = 0.0;  // the MSD window actually fitted
  double sample_strain = 0.0, coarse_strain = 0.0;
  long samples = 0, particles = 0;
  std::vector<std::string> warnings;
};

// The diffusion analysis accumulated sample by sample while the run goes, so that neither the
// trajectory nor the checkpoint has to hold the measured window (docs/model.md section 9):
// - the VACF of v_y and the MSD of y (and of the non-affine x displacement) on a multiple-tau
//   grid (MultipleTauCorrelator), every sample an origin, sums kept per sixteenth of an error
//   block;
// - the every-origin MSD and the increment products of y on samples coarse_strain apart
//   (IncrementGram): D and its error bar (msd_slope_error).
// Memory is that of ~100 samples per signal (independent of the window's length) plus a few
// numbers per coarse sample. On the same samples it equals the frame analysis to round-off.
class DiffusionAccumulator {
 public:
  DiffusionAccumulator() = default;
  // particles: mobile discs; bulk: every sample comes with a bulk mask; non_affine_x: with the
  // x displacement relative to the imposed flow.
  DiffusionAccumulator(const DiffusionSettings& s, double sample_strain, long particles, bool bulk,
                       bool non_affine_x);
  // One sample: particles values each (bulk: 1 = the disc is in the bulk now).
  void add(const double* y, const double* vy, const double* x = nullptr,
           const std::uint8_t* bulk = nullptr);
  long samples() const { return vacf_.samples(); }
  long particles() const { return particles_; }
  // The analysis of the samples so far; throws std::invalid_argument if they are too few.
  DiffusionReport report() const;
  void serialize(Archive& a);

 private:
  // A displacement velocity over k 2^level samples, taken every 2^level samples from the MSD
  // correlator's stored past (so it needs no history of its own).
  struct Interval {
    int level = 0;
    long k = 1, mini = 1;
    MultipleTauCorrelator c;
  };
  // The parts of report(), each filling its part of r.
  void fit_msd(DiffusionReport& r) const;
  void velocities(DiffusionReport& r, long block_samples, long blocks) const;
  void d_error_bar(DiffusionReport& r) const;
  void bulk_only(DiffusionReport& r, long block_samples, long blocks) const;
  void interval_velocities(DiffusionReport& r) const;
  void x_diffusion(DiffusionReport& r) const;

  DiffusionSettings s_;
  double dt_ = 0.0;
  long particles_ = 0, mini_ = 1, stride_ = 1;
  bool bulk_ = false, x_ = false;
  MultipleTauCorrelator vacf_, msd_, msd_x_;
  IncrementGram coarse_;
  std::vector<Interval> intervals_;
  std::vector<double> u_;  // scratch
};

// The same analysis of frames uniformly spaced by frame_strain (frames x particles), fed to a
// DiffusionAccumulator one frame at a time. bulk_mask (optional, 0/1): which disc counts as
// bulk at which frame.
DiffusionReport analyse_diffusion(const Eigen::MatrixXd& y, const Eigen::MatrixXd& vy,
                                  double frame_strain, const DiffusionSettings& settings,
                                  const Eigen::MatrixXd* bulk_mask = nullptr);

// 1 where a disc's centre lies at least `exclusion` above the bottom wall's mean centre line
// and below the top wall's at that frame (y: frames x particles; bottom, top: one per frame).
Eigen::MatrixXd bulk_mask(const Eigen::MatrixXd& y, const Eigen::VectorXd& bottom,
                          const Eigen::VectorXd& top, double exclusion);

// Adds D, D_err, D_regression_stderr, dv, dv_err, psi, psi_err, psi_e, psi_zero, psi_full
// (each with _err), step_length, msd_window, msd_window_slope, the *_bulk values, ... to summary.
void add_to_summary(const DiffusionReport& r, nlohmann::json& summary);

}  // namespace sheardiff
