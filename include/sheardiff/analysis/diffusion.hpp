#pragma once
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sheardiff/analysis/time_series.hpp"

namespace sheardiff {

struct DiffusionSettings {
  double window_lo = 8.0, window_hi = 15.0;  // MSD fit window, strain
  long reference_times = 1000;               // t0 drawn in the measured window
  double vacf_max_lag = 2.0;                 // strain; Psi gammadot <= ~0.2 for J <= 0.1
  std::uint64_t seed = 1;
};

// Self-diffusion in the gradient direction (seed paper section 3, model.md section 9) from
// frames uniformly spaced by frame_strain: y (frames x particles, unwrapped, in d) and vy
// (frames x particles, v_y / gammadot, in d per unit strain). Times are strains, so D comes out
// in gammadot d^2, dv in gammadot d and Psi in 1/gammadot.
struct DiffusionReport {
  MsdResult msd;
  Autocorrelation vacf;
  DiffusionFit fit;
  Persistence persistence;
  double dv = 0.0;
  double step_length = 0.0;   // dv Psi
  double consistency = 0.0;   // D / (dv^2 Psi), 1 if the VACF integral carries the diffusion
  double window_lo = 0.0, window_hi = 0.0;  // the MSD window actually fitted
  double frame_strain = 0.0;
  long frames = 0, particles = 0, reference_times = 0;
  std::vector<std::string> warnings;
};

DiffusionReport analyse_diffusion(const Eigen::MatrixXd& y, const Eigen::MatrixXd& vy,
                                  double frame_strain, const DiffusionSettings& settings);

// Adds D, D_stderr, dv, psi, psi_e, step_length, msd_window, msd_window_slope, ... to summary.
void add_to_summary(const DiffusionReport& r, nlohmann::json& summary);
// DIR/analysis.h5: /msd/{lag, msd, samples}, /vacf/{lag, c}, fit results as attributes of /.
void write_analysis_file(const DiffusionReport& r, const std::filesystem::path& file);

}  // namespace sheardiff
