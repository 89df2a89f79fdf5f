#include "sheardiff/analysis/time_series.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <unsupported/Eigen/FFT>

#include "sheardiff/analysis/power_law.hpp"

namespace sheardiff {
namespace {

void check_series(const char* who, const Eigen::MatrixXd& y, double dt, long max_lag) {
  if (y.rows() < 2 || y.cols() < 1) {
    throw std::invalid_argument(fmt::format(
        "{}: need at least 2 frames and 1 particle, got {} x {}", who, y.rows(), y.cols()));
  }
  if (!(dt > 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument(fmt::format("{}: dt = {} must be positive and finite", who, dt));
  }
  if (max_lag < 0 || max_lag >= y.rows()) {
    throw std::invalid_argument(fmt::format("{}: max_lag = {} must be in [0, frames - 1 = {}]", who,
                                            max_lag, y.rows() - 1));
  }
  if (!y.allFinite()) throw std::invalid_argument(fmt::format("{}: non-finite samples", who));
}

std::vector<double> lag_times(double dt, long max_lag) {
  std::vector<double> lag(static_cast<std::size_t>(max_lag) + 1);
  for (long k = 0; k <= max_lag; ++k)
    lag[static_cast<std::size_t>(k)] = static_cast<double>(k) * dt;
  return lag;
}

// Sums over particles of sum_i x_i x_{i+k} (k = 0..max_lag) by the Wiener-Khinchin theorem.
// Zero-padding to N >= F + max_lag suffices: a circular lag k only wraps terms with i >= N - k
// >= F, which are the zeros. N is a power of two (kissfft's fastest radix, and the real-input
// path needs a multiple of 4). The power spectra are summed before a single inverse FFT since
// the inverse is linear: P forward real FFTs + 1 inverse, O(P N log N) time, O(N) memory.
// If subtract_mean, each particle's series is centred first (MSD is shift-invariant and this
// keeps S1 - 2 S2 from cancelling a large <x^2>); if s1 is given, it receives the sums of
// sum_{i<F-k} (x_i^2 + x_{i+k}^2), the S1 term of the MSD, from running sums of squares.
std::vector<double> summed_autocorrelation(const Eigen::MatrixXd& y, long max_lag,
                                           bool subtract_mean, std::vector<double>* s1) {
  const Eigen::Index frames = y.rows();
  Eigen::Index nfft = 4;
  while (nfft < frames + max_lag) nfft *= 2;
  const std::size_t nbins = static_cast<std::size_t>(nfft / 2 + 1);

  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);  // real input: only the non-negative bins
  std::vector<double> buf(static_cast<std::size_t>(nfft), 0.0);
  std::vector<std::complex<double>> spec(nbins);
  std::vector<double> power(nbins, 0.0);
  std::vector<double> cumsq(static_cast<std::size_t>(frames) + 1);
  if (s1) s1->assign(static_cast<std::size_t>(max_lag) + 1, 0.0);

  for (Eigen::Index p = 0; p < y.cols(); ++p) {
    const double mean = subtract_mean ? y.col(p).mean() : 0.0;
    for (Eigen::Index i = 0; i < frames; ++i) buf[static_cast<std::size_t>(i)] = y(i, p) - mean;
    // buf[frames..nfft) stays zero from the initialisation: the padding.
    fft.fwd(spec.data(), buf.data(), nfft);
    for (std::size_t b = 0; b < nbins; ++b) power[b] += std::norm(spec[b]);
    if (s1) {
      cumsq[0] = 0.0;
      for (Eigen::Index i = 0; i < frames; ++i) {
        const double xi = buf[static_cast<std::size_t>(i)];
        cumsq[static_cast<std::size_t>(i) + 1] = cumsq[static_cast<std::size_t>(i)] + xi * xi;
      }
      const double total = cumsq[static_cast<std::size_t>(frames)];
      for (long k = 0; k <= max_lag; ++k) {
        // x_i^2 over the first F-k frames plus x_{i+k}^2 over the last F-k frames.
        (*s1)[static_cast<std::size_t>(k)] += cumsq[static_cast<std::size_t>(frames - k)] +
                                              (total - cumsq[static_cast<std::size_t>(k)]);
      }
    }
  }
  for (std::size_t b = 0; b < nbins; ++b) spec[b] = std::complex<double>(power[b], 0.0);
  fft.inv(buf.data(), spec.data(), nfft);  // scaled by 1/N (Unscaled flag not set)
  return std::vector<double>(buf.begin(), buf.begin() + max_lag + 1);
}

// Unbiased integer in [0, m) from a standard-specified engine (std distributions are not
// reproducible across standard libraries): reject the incomplete last block of 2^64.
std::uint64_t uniform_below(std::mt19937_64& rng, std::uint64_t m) {
  const std::uint64_t threshold = (0 - m) % m;  // 2^64 mod m
  for (;;) {
    const std::uint64_t r = rng();
    if (r >= threshold) return r % m;
  }
}

}  // namespace

MsdResult mean_square_displacement(const Eigen::MatrixXd& y, double dt, long max_lag) {
  check_series("mean_square_displacement", y, dt, max_lag);
  // MSD(k) = [S1(k) - 2 S2(k)] / (F - k) per particle, summed over particles: O(P N log N).
  std::vector<double> s1;
  const std::vector<double> s2 = summed_autocorrelation(y, max_lag, true, &s1);
  const long frames = static_cast<long>(y.rows());
  const long particles = static_cast<long>(y.cols());
  MsdResult out;
  out.lag = lag_times(dt, max_lag);
  out.msd.resize(out.lag.size());
  out.samples.resize(out.lag.size());
  for (long k = 0; k <= max_lag; ++k) {
    const auto i = static_cast<std::size_t>(k);
    out.samples[i] = particles * (frames - k);
    // Clamp roundoff below zero (e.g. a motionless particle set).
    out.msd[i] = std::max(0.0, s1[i] - 2.0 * s2[i]) / static_cast<double>(out.samples[i]);
  }
  out.msd[0] = 0.0;  // exact by definition; the FFT would leave roundoff
  return out;
}

MsdResult mean_square_displacement(const Eigen::MatrixXd& y, double dt, long max_lag,
                                   const std::vector<long>& reference_frames) {
  check_series("mean_square_displacement", y, dt, max_lag);
  if (reference_frames.empty()) {
    throw std::invalid_argument("mean_square_displacement: no reference frames");
  }
  const long frames = static_cast<long>(y.rows());
  for (long t0 : reference_frames) {
    if (t0 < 0 || t0 + max_lag >= frames) {
      throw std::invalid_argument(
          fmt::format("mean_square_displacement: reference frame {} with max_lag {} leaves [0, {})",
                      t0, max_lag, frames));
    }
  }
  // Frames as contiguous columns so each lag is one vectorised difference over particles.
  const Eigen::MatrixXd by_frame = y.transpose();
  std::vector<double> acc(static_cast<std::size_t>(max_lag) + 1, 0.0);
  // O(len(t0) * P * max_lag).
  for (long t0 : reference_frames) {
    const auto base = by_frame.col(t0);
    for (long k = 1; k <= max_lag; ++k) {
      acc[static_cast<std::size_t>(k)] += (by_frame.col(t0 + k) - base).squaredNorm();
    }
  }
  MsdResult out;
  out.lag = lag_times(dt, max_lag);
  out.msd.resize(out.lag.size());
  const long pairs = static_cast<long>(reference_frames.size()) * static_cast<long>(y.cols());
  out.samples.assign(out.lag.size(), pairs);
  for (std::size_t i = 0; i < acc.size(); ++i) out.msd[i] = acc[i] / static_cast<double>(pairs);
  return out;
}

std::vector<long> draw_reference_frames(long first, long last_exclusive, long max_lag, long n,
                                        std::uint64_t seed) {
  if (first < 0 || max_lag < 0 || n < 1) {
    throw std::invalid_argument(
        fmt::format("draw_reference_frames: need first >= 0, max_lag >= 0, n >= 1 (got {}, {}, {})",
                    first, max_lag, n));
  }
  const long available = last_exclusive - max_lag - first;
  if (available < 1) {
    throw std::invalid_argument(fmt::format("draw_reference_frames: empty range [{}, {} - {})",
                                            first, last_exclusive, max_lag));
  }
  std::mt19937_64 rng(seed);
  std::vector<long> out;
  out.reserve(static_cast<std::size_t>(n));
  // More draws than frames: use every frame equally often, draw only the remainder.
  for (long rep = 0; rep < n / available; ++rep) {
    for (long t = 0; t < available; ++t) out.push_back(first + t);
  }
  const long extra = n % available;
  if (extra > 0) {
    // Partial Fisher-Yates: extra distinct frames, uniformly.
    std::vector<long> pool(static_cast<std::size_t>(available));
    std::iota(pool.begin(), pool.end(), first);
    for (long i = 0; i < extra; ++i) {
      const auto j =
          static_cast<long>(static_cast<std::uint64_t>(i) +
                            uniform_below(rng, static_cast<std::uint64_t>(available - i)));
      std::swap(pool[static_cast<std::size_t>(i)], pool[static_cast<std::size_t>(j)]);
      out.push_back(pool[static_cast<std::size_t>(i)]);
    }
  }
  std::sort(out.begin(), out.end());  // ascending t0: friendlier memory access
  return out;
}

Autocorrelation velocity_autocorrelation(const Eigen::MatrixXd& v, double dt, long max_lag) {
  check_series("velocity_autocorrelation", v, dt, max_lag);
  // O(P N log N); unbiased: lag k averages its own P (F - k) pairs.
  const std::vector<double> r = summed_autocorrelation(v, max_lag, false, nullptr);
  Autocorrelation out;
  out.lag = lag_times(dt, max_lag);
  out.c.resize(out.lag.size());
  const double particles = static_cast<double>(v.cols());
  for (long k = 0; k <= max_lag; ++k) {
    const auto i = static_cast<std::size_t>(k);
    out.c[i] = r[i] / (particles * static_cast<double>(v.rows() - k));
  }
  return out;
}

Persistence persistence_time(const Autocorrelation& ac) {
  if (ac.lag.size() != ac.c.size() || ac.c.size() < 2) {
    throw std::invalid_argument(
        fmt::format("persistence_time: need matching lag/c of at least 2 values (got {} and {})",
                    ac.lag.size(), ac.c.size()));
  }
  for (std::size_t i = 0; i < ac.c.size(); ++i) {
    if (!std::isfinite(ac.c[i]) || !std::isfinite(ac.lag[i])) {
      throw std::invalid_argument(fmt::format("persistence_time: non-finite value at {}", i));
    }
  }
  Persistence out;
  out.c0 = ac.c[0];
  if (!(out.c0 > 0.0)) {
    throw std::invalid_argument(fmt::format("persistence_time: C(0) = {} must be > 0", out.c0));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.psi_e = nan;
  out.psi_zero = nan;
  const double inv_e = std::exp(-1.0);
  double prev = 1.0;  // C / C(0) at the previous lag
  for (std::size_t k = 1; k < ac.c.size(); ++k) {
    const double t0 = ac.lag[k - 1], t1 = ac.lag[k];
    const double cur = ac.c[k] / out.c0;
    out.psi_full += 0.5 * (prev + cur) * (t1 - t0);
    if (std::isnan(out.psi_e) && cur <= inv_e) {
      out.psi_e = t0 + (t1 - t0) * (prev - inv_e) / (prev - cur);
    }
    if (!out.crossed_zero) {
      if (cur <= 0.0) {
        // psi stops at the interpolated crossing: beyond it C is noise whose integral only
        // adds variance (and a spurious sign).
        const double tc = t0 + (t1 - t0) * prev / (prev - cur);
        out.psi += 0.5 * prev * (tc - t0);
        out.psi_zero = tc;
        out.crossed_zero = true;
      } else {
        out.psi += 0.5 * (prev + cur) * (t1 - t0);
      }
    }
    prev = cur;
  }
  return out;
}

DiffusionFit fit_diffusion(const MsdResult& msd, double t_lo, double t_hi) {
  if (msd.lag.size() != msd.msd.size()) {
    throw std::invalid_argument(
        fmt::format("fit_diffusion: {} lags but {} msd values", msd.lag.size(), msd.msd.size()));
  }
  if (!(t_lo < t_hi) || !std::isfinite(t_lo) || !std::isfinite(t_hi)) {
    throw std::invalid_argument(
        fmt::format("fit_diffusion: window [{}, {}] is not a finite interval", t_lo, t_hi));
  }
  // Lags are k * dt, so a window edge at a "round" time may miss by an ulp.
  const double tol = 1e-9 * std::max(std::abs(t_lo), std::abs(t_hi));
  std::vector<double> t, m, logt, logm;
  for (std::size_t i = 0; i < msd.lag.size(); ++i) {
    if (msd.lag[i] < t_lo - tol || msd.lag[i] > t_hi + tol) continue;
    t.push_back(msd.lag[i]);
    m.push_back(msd.msd[i]);
    if (msd.lag[i] > 0.0 && msd.msd[i] > 0.0) {
      logt.push_back(std::log(msd.lag[i]));
      logm.push_back(std::log(msd.msd[i]));
    }
  }
  if (t.size() < 3) {
    throw std::invalid_argument(fmt::format(
        "fit_diffusion: window [{}, {}] holds {} lags, need at least 3", t_lo, t_hi, t.size()));
  }
  // Einstein: MSD = 2 D t + const in the diffusive regime.
  const LineFit line = fit_line(t, m);
  DiffusionFit out;
  out.d = 0.5 * line.slope;
  out.d_stderr = 0.5 * line.slope_stderr;
  out.intercept = line.intercept;
  out.points = line.n;
  out.loglog_slope =
      logt.size() >= 3 ? fit_line(logt, logm).slope : std::numeric_limits<double>::quiet_NaN();
  return out;
}

}  // namespace sheardiff
