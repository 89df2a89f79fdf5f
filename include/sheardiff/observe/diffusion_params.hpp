#pragma once
// The self-diffusion analysis (observe/diffusion_observer.hpp): its parameters and keys,
// declared once; the configuration schema, its validation and docs/config.md read them from
// here.
#include <cstdint>
#include <vector>

namespace sheardiff {

struct DiffusionParams {
  bool diffusion = true;                   // MSD, VACF, dv, Psi, D over the measured window
  double msd_window_lo = 8.0;              // strain
  double msd_window_hi = 15.0;             // strain
  std::int64_t reference_times = 1000;     // unused: every sample is an origin
  double vacf_max_lag = 2.0;               // strain
  double error_block = 3.0;                // strain: time blocks of the error bars
  double sample_strain = 0.0;              // strain between samples; 0 = output.frame_strain / 10
  double coarse_strain = 0.0;              // strain between the samples D comes from; 0 = auto
  std::vector<double> velocity_intervals;  // strain: displacement-velocity definitions

  // Keys: the schema's section adapter (src/config.cpp).
  template <class Keys>
  static void declare(Keys& k) {
    using P = DiffusionParams;
    k.boolean("analysis.diffusion", &P::diffusion,
              "Self-diffusion analysis over the measured window (steady state, or after "
              "run.transient_strain): MSD, D, dv, VACF, Psi; writes DIR/analysis.h5. Off = it "
              "costs nothing.");
    k.real("analysis.msd_window_lo", &P::msd_window_lo, 0.0, 1e5, false, "1 (strain)",
           "Start of the MSD fit window (seed: 8).");
    k.real("analysis.msd_window_hi", &P::msd_window_hi, 0.0, 1e5, true, "1 (strain)",
           "End of the MSD fit window (seed: 15).");
    k.integer("analysis.reference_times", &P::reference_times, 1, 1e8, "",
              "Unused (kept so that older configs load): every sample of the measured window is "
              "a reference time t0 of the MSD.");
    k.real("analysis.sample_strain", &P::sample_strain, 0.0, 1.0, false, "1 (strain)",
           "Strain between two samples of the diffusion analysis, taken during the run "
           "(independent of the trajectory); 0 = output.frame_strain / 10, i.e. ~100 samples "
           "per persistence time.");
    k.real_list("analysis.velocity_intervals", &P::velocity_intervals, 0.0, 1.0, true, "1 (strain)",
                "Also report dv and Psi of the displacement velocity (y(t + Delta) - y(t)) / "
                "Delta for each interval Delta here (rounded to the analysis's grid), beside "
                "those of the instantaneous velocities; e.g. [0.0035, 0.01]. Each costs ~80 "
                "samples of memory.");
    k.real("analysis.coarse_strain", &P::coarse_strain, 0.0, 1e3, false, "1 (strain)",
           "Strain between the samples D and its error bar are fitted to (every one an origin "
           "of the MSD), rounded to a whole number of samples; 0 = min(0.2, "
           "analysis.msd_window_hi / 75), i.e. 36 lags in the seed's window.");
    k.real("analysis.vacf_max_lag", &P::vacf_max_lag, 0.0, 1e3, true, "1 (strain)",
           "Longest lag of the velocity autocorrelation.");
    k.real("analysis.error_block", &P::error_block, 0.0, 1e5, true, "1 (strain)",
           "Time blocks of the error bars (phi, mu, dv, Psi, D): longer than the correlation "
           "time (>= 10 Psi); at least 4 blocks are used.");
  }
};

}  // namespace sheardiff
