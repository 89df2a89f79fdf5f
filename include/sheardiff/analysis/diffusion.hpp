#pragma once
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sheardiff/analysis/time_series.hpp"
#include "sheardiff/analysis/uncertainty.hpp"

namespace sheardiff {

struct DiffusionSettings {
  double window_lo = 8.0, window_hi = 15.0;  // MSD fit window, strain
  long reference_times = 1000;               // t0 drawn in the measured window
  double vacf_max_lag = 2.0;                 // strain; Psi gammadot <= ~0.2 for J <= 0.1
  double error_block = 3.0;                  // strain: time blocks of the error bars
  std::uint64_t seed = 1;
};

// Self-diffusion in the gradient direction (seed paper section 3, docs/model.md section 9) from
// frames uniformly spaced by frame_strain: y (frames x particles, unwrapped, in d) and vy
// (frames x particles, v_y / gammadot, in d per unit strain). Times are strains, so D comes out
// in gammadot d^2, dv in gammadot d and Psi in 1/gammadot.
struct DiffusionReport {
  MsdResult msd;
  Autocorrelation vacf;
  DiffusionFit fit;           // the seed's estimate (its reference times), regression error
  MsdSlopeError d_error;      // the error bar of D from the run's own time blocks
  PersistenceEstimate vel;    // dv, Psi (every definition) and their jackknife errors
  Persistence persistence;    // = vel.p
  double dv = 0.0;
  // The same analysis restricted to discs in the bulk (away from the walls) at the reference
  // time, when a bulk mask was given: bulk_fraction of the (disc, time) samples.
  bool has_bulk = false;
  MsdResult msd_bulk;
  DiffusionFit fit_bulk;
  PersistenceEstimate vel_bulk;
  double bulk_fraction = 0.0;
  double error_block = 0.0;   // strain, as used
  double step_length = 0.0;   // dv Psi
  double consistency = 0.0;   // D / (dv^2 Psi), 1 if the VACF integral carries the diffusion
  double window_lo = 0.0, window_hi = 0.0;  // the MSD window actually fitted
  double frame_strain = 0.0;
  long frames = 0, particles = 0, reference_times = 0;
  std::vector<std::string> warnings;
};

// bulk_mask (optional, frames x particles, 0/1): which disc counts as bulk at which frame.
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
// DIR/analysis.h5: /msd/{lag, msd, samples}, /vacf/{lag, c}, fit results as attributes of /.
void write_analysis_file(const DiffusionReport& r, const std::filesystem::path& file);

}  // namespace sheardiff
