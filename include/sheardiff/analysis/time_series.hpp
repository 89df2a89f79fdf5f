#pragma once
#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace sheardiff {

// Trajectory analysis of frames sampled uniformly in time (docs/model.md section 9, seed
// section 3).
// Inputs are frames x particles (row = frame, column = particle, so a particle's history is
// contiguous). dt is the frame spacing in whatever unit the caller uses (strain or time); the
// functions never assume one. Bad input throws std::invalid_argument.

// msd[k] at lag[k] = k dt, k = 0..max_lag; samples[k] = number of (particle, t0) pairs averaged.
struct MsdResult {
  std::vector<double> lag;
  std::vector<double> msd;
  std::vector<long> samples;
};

// MSD over all particles and every frame as reference time t0 (lag k has P (F - k) pairs).
// Uses MSD(k) = S1(k) - 2 S2(k) with S2 the autocorrelation via zero-padded FFTs.
// Cost O(P * N log N), N >= F + max_lag the FFT length, memory O(N); requires max_lag < F.
MsdResult mean_square_displacement(const Eigen::MatrixXd& y, double dt, long max_lag);

// MSD over all particles and the given reference frames t0 (repeats count repeatedly), as the
// seed does with 1000 random t0. Every t0 must satisfy 0 <= t0 and t0 + max_lag < F, so every
// lag averages the same set. Cost O(len(t0) * P * max_lag), vectorised across particles.
MsdResult mean_square_displacement(const Eigen::MatrixXd& y, double dt, long max_lag,
                                   const std::vector<long>& reference_frames);

// n reference frames drawn uniformly from [first, last_exclusive - max_lag), sorted. Distinct if
// n <= available; otherwise every frame appears floor(n / available) times plus n % available
// distinct extras (with replacement, stratified). Reproducible for a given seed (mt19937_64 and
// our own integer mapping, not the implementation-defined std distributions).
std::vector<long> draw_reference_frames(long first, long last_exclusive, long max_lag, long n,
                                        std::uint64_t seed);

// C(k dt) = <v(t0) v(t0 + k dt)> over particles and all t0, unbiased (each lag divided by its
// own number of pairs P (F - k)), k = 0..max_lag. No mean is subtracted: pass fluctuations.
// Cost O(P * N log N), N >= F + max_lag.
struct Autocorrelation {
  std::vector<double> lag;
  std::vector<double> c;
};
Autocorrelation velocity_autocorrelation(const Eigen::MatrixXd& v, double dt, long max_lag);

// psi = trapezoid integral of C / C(0) from 0 to the first zero crossing of C (linearly
// interpolated; crossed_zero = true) or to the last lag (crossed_zero = false): the caller sets
// the cut-off through max_lag. psi_e = first time C / C(0) reaches 1/e (linear interpolation),
// NaN if it never does. c0 = C(0) = dv^2. Throws if C(0) <= 0 or fewer than 2 lags.
// Two more definitions, for comparing with papers that use them: psi_zero = the first zero
// crossing time itself (NaN if C stays positive), psi_full = the integral of C / C(0) over every
// lag given (the Green-Kubo value, D / dv^2 once the lags reach the diffusive regime).
struct Persistence {
  double psi = 0;
  double psi_e = 0;
  double psi_zero = 0;
  double psi_full = 0;
  bool crossed_zero = false;
  double c0 = 0;
};
Persistence persistence_time(const Autocorrelation& ac);

// OLS msd = intercept + 2 d t over lags in [t_lo, t_hi]; d_stderr = slope stderr / 2 (assumes
// independent residuals, so it underestimates the error of a correlated MSD curve).
// loglog_slope: slope of the log-log line fit over the window's points with t > 0, msd > 0
// (~1 diffusive, ~2 ballistic; NaN if fewer than 3 such points). Throws if < 3 points.
struct DiffusionFit {
  double d = 0, d_stderr = 0, intercept = 0, loglog_slope = 0;
  long points = 0;
};
DiffusionFit fit_diffusion(const MsdResult& msd, double t_lo, double t_hi);

}  // namespace sheardiff
