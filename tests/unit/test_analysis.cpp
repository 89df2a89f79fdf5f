// Analysis library (docs/model.md section 9, seed section 3 and Appendices B, D): MSD in both modes
// against brute force, ballistic and random-walk references; VACF / persistence time of an
// Ornstein-Uhlenbeck velocity and D = dv^2 Psi on its integrated positions; power-law and
// dilatancy fits with calibrated standard errors; bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "sheardiff/analysis/power_law.hpp"
#include "sheardiff/analysis/time_series.hpp"

namespace sheardiff {
namespace {

// frames x particles random walks with Gaussian steps of variance 2 D dt, started at offset.
Eigen::MatrixXd random_walks(long frames, long particles, double d, double dt, double offset,
                             unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> step(0.0, std::sqrt(2.0 * d * dt));
  Eigen::MatrixXd y(frames, particles);
  for (long p = 0; p < particles; ++p) {
    y(0, p) = offset + static_cast<double>(p);
    for (long i = 1; i < frames; ++i) y(i, p) = y(i - 1, p) + step(rng);
  }
  return y;
}

std::vector<double> brute_msd(const Eigen::MatrixXd& y, long max_lag,
                              const std::vector<long>* t0s = nullptr) {
  std::vector<double> out(static_cast<std::size_t>(max_lag) + 1, 0.0);
  for (long k = 0; k <= max_lag; ++k) {
    double s = 0;
    long n = 0;
    for (long p = 0; p < y.cols(); ++p) {
      if (t0s) {
        for (long t0 : *t0s) {
          s += std::pow(y(t0 + k, p) - y(t0, p), 2);
          ++n;
        }
      } else {
        for (long t0 = 0; t0 + k < y.rows(); ++t0) {
          s += std::pow(y(t0 + k, p) - y(t0, p), 2);
          ++n;
        }
      }
    }
    out[static_cast<std::size_t>(k)] = s / static_cast<double>(n);
  }
  return out;
}

std::vector<double> logspace(double lo, double hi, int n) {
  std::vector<double> x(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    x[static_cast<std::size_t>(i)] = lo * std::pow(hi / lo, i / (n - 1.0));
  return x;
}

TEST(AnalysisMsd, FftModeEqualsBruteForce) {
  // Offset 100 >> displacements: checks that centring keeps S1 - 2 S2 from cancelling.
  const Eigen::MatrixXd y = random_walks(150, 7, 0.5, 0.1, 100.0, 11);
  const long max_lag = 149;  // every lag, including the single-pair one
  const MsdResult fft = mean_square_displacement(y, 0.1, max_lag);
  const std::vector<double> ref = brute_msd(y, max_lag);
  ASSERT_EQ(fft.msd.size(), ref.size());
  EXPECT_EQ(fft.msd[0], 0.0);
  for (std::size_t k = 1; k < ref.size(); ++k) {
    EXPECT_NEAR(fft.msd[k], ref[k], 1e-9 * ref[k]) << "lag " << k;
    EXPECT_EQ(fft.samples[k], 7 * (150 - static_cast<long>(k)));
    EXPECT_NEAR(fft.lag[k], 0.1 * static_cast<double>(k), 1e-12);
  }
}

TEST(AnalysisMsd, ReferenceModeEqualsBruteForce) {
  const Eigen::MatrixXd y = random_walks(120, 5, 0.5, 0.1, 3.0, 12);
  const std::vector<long> t0s = {0, 3, 3, 17, 50, 99};  // repeats weigh twice
  const MsdResult m = mean_square_displacement(y, 0.1, 20, t0s);
  const std::vector<double> ref = brute_msd(y, 20, &t0s);
  for (std::size_t k = 0; k < ref.size(); ++k) {
    EXPECT_NEAR(m.msd[k], ref[k], 1e-12 * (1.0 + ref[k])) << "lag " << k;
    EXPECT_EQ(m.samples[k], 30);
  }
}

TEST(AnalysisMsd, BallisticIsExactQuadratic) {
  const long frames = 256, particles = 6;
  const double dt = 0.1;
  Eigen::MatrixXd y(frames, particles);
  double v2 = 0;
  for (long p = 0; p < particles; ++p) {
    const double v = 0.3 + 0.2 * static_cast<double>(p) * (p % 2 ? -1.0 : 1.0);
    v2 += v * v / particles;
    for (long i = 0; i < frames; ++i) y(i, p) = 2.0 + v * static_cast<double>(i) * dt;
  }
  const long max_lag = 100;
  const MsdResult all = mean_square_displacement(y, dt, max_lag);
  const MsdResult some =
      mean_square_displacement(y, dt, max_lag, draw_reference_frames(0, frames, max_lag, 50, 5));
  for (long k = 1; k <= max_lag; ++k) {
    const double t = static_cast<double>(k) * dt;
    EXPECT_NEAR(all.msd[static_cast<std::size_t>(k)], v2 * t * t, 1e-9 * v2 * t * t);
    EXPECT_NEAR(some.msd[static_cast<std::size_t>(k)], v2 * t * t, 1e-9 * v2 * t * t);
  }
  EXPECT_NEAR(fit_diffusion(all, 0.5, 10.0).loglog_slope, 2.0, 1e-9);
  EXPECT_NEAR(fit_diffusion(some, 0.5, 10.0).loglog_slope, 2.0, 1e-9);
}

// Gaussian walk: MSD = 2 D t exactly in expectation. The slope's relative noise grows like
// sqrt(t_hi / (P F)): 400 walkers with window lags 20..100 gave ~0.9% sd over seeds, too close
// to the 1% target, so 1000 x 4000 frames and window lags 5..25 of 50 (~0.3% sd measured).
TEST(AnalysisMsd, RandomWalkRecoversDiffusionBothModes) {
  const double d = 0.3, dt = 0.02;
  const long frames = 4000, particles = 1000, max_lag = 50;
  const Eigen::MatrixXd y = random_walks(frames, particles, d, dt, 0.0, 2024);
  const MsdResult all = mean_square_displacement(y, dt, max_lag);
  const DiffusionFit fa = fit_diffusion(all, 5 * dt, 25 * dt);
  EXPECT_EQ(fa.points, 21);
  EXPECT_NEAR(fa.d, d, 0.01 * d);
  EXPECT_NEAR(fa.loglog_slope, 1.0, 0.02);
  EXPECT_GT(fa.d_stderr, 0.0);

  const std::vector<long> t0s = draw_reference_frames(0, frames, max_lag, 1000, 77);
  const MsdResult some = mean_square_displacement(y, dt, max_lag, t0s);
  const DiffusionFit fs = fit_diffusion(some, 5 * dt, 25 * dt);
  EXPECT_NEAR(fs.d, d, 0.01 * d);
  EXPECT_NEAR(fs.loglog_slope, 1.0, 0.02);
  EXPECT_EQ(some.samples[1], 1000 * particles);
}

TEST(AnalysisMsd, DrawReferenceFramesIsSeededAndInRange) {
  const std::vector<long> a = draw_reference_frames(100, 5000, 400, 1000, 42);
  EXPECT_EQ(a, draw_reference_frames(100, 5000, 400, 1000, 42));
  EXPECT_NE(a, draw_reference_frames(100, 5000, 400, 1000, 43));
  ASSERT_EQ(a.size(), 1000u);
  EXPECT_TRUE(std::is_sorted(a.begin(), a.end()));
  EXPECT_EQ(std::adjacent_find(a.begin(), a.end()), a.end());  // distinct
  EXPECT_GE(a.front(), 100);
  EXPECT_LT(a.back(), 4600);
  // Uniform: mean of the 1000 draws near the middle of [100, 4600) (sd ~ 41).
  double mean = 0;
  for (long t : a) mean += static_cast<double>(t) / 1000.0;
  EXPECT_NEAR(mean, 2349.5, 200.0);
  // More draws than frames: each of the 10 frames twice, plus 5 distinct extras.
  const std::vector<long> b = draw_reference_frames(0, 20, 10, 25, 1);
  ASSERT_EQ(b.size(), 25u);
  for (long t = 0; t < 10; ++t) {
    const auto c = std::count(b.begin(), b.end(), t);
    EXPECT_TRUE(c == 2 || c == 3);
  }
}

TEST(AnalysisVacf, FftEqualsBruteForce) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd v(90, 4);
  for (Eigen::Index i = 0; i < v.size(); ++i) v.data()[i] = 0.2 + n01(rng);
  const Autocorrelation ac = velocity_autocorrelation(v, 0.5, 89);
  for (long k = 0; k <= 89; ++k) {
    double s = 0;
    for (long p = 0; p < 4; ++p)
      for (long t0 = 0; t0 + k < 90; ++t0) s += v(t0, p) * v(t0 + k, p);
    const double ref = s / (4.0 * static_cast<double>(90 - k));
    EXPECT_NEAR(ac.c[static_cast<std::size_t>(k)], ref, 1e-12) << "lag " << k;
  }
  EXPECT_DOUBLE_EQ(ac.lag[3], 1.5);
}

TEST(AnalysisVacf, PersistenceOfTriangleIsExact) {
  // C = 2 (1 - t / 3) crosses zero at t = 3 between samples: Psi = 3 / 2, psi_e = 3 (1 - 1/e).
  Autocorrelation ac;
  for (int k = 0; k <= 20; ++k) {
    ac.lag.push_back(0.4 * k);
    ac.c.push_back(2.0 * (1.0 - 0.4 * k / 3.0));
  }
  const Persistence p = persistence_time(ac);
  EXPECT_TRUE(p.crossed_zero);
  EXPECT_NEAR(p.psi, 1.5, 1e-12);
  EXPECT_NEAR(p.psi_e, 3.0 * (1.0 - std::exp(-1.0)), 1e-12);
  EXPECT_DOUBLE_EQ(p.c0, 2.0);
  // Cut before the crossing: integral to the last lag, no 1/e time reached.
  ac.lag.resize(3);
  ac.c.resize(3);
  const Persistence q = persistence_time(ac);
  EXPECT_FALSE(q.crossed_zero);
  EXPECT_NEAR(q.psi, 0.8 - 0.8 * 0.8 / 6.0, 1e-12);
  EXPECT_TRUE(std::isnan(q.psi_e));
}

// Ornstein-Uhlenbeck velocity, C(t) = sigma^2 exp(-t / tau), exact discretisation with
// dt = tau / 20, 800 particles x 20000 frames (1000 tau each, 8e5 correlation times in all;
// half as many gave Psi errors up to 1.2% over seeds, too close to the 2% target).
TEST(AnalysisVacf, OrnsteinUhlenbeckPersistenceAndDiffusion) {
  const double tau = 1.0, sigma = 0.7, dt = tau / 20.0;
  const long frames = 20000, particles = 800;
  const double r = std::exp(-dt / tau), kick = sigma * std::sqrt(1.0 - r * r);
  std::mt19937_64 rng(31415);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd v(frames, particles);  // 128 MB; reused in place for the positions below
  for (long p = 0; p < particles; ++p) {
    v(0, p) = sigma * n01(rng);  // stationary start: no transient to discard
    for (long i = 1; i < frames; ++i) v(i, p) = r * v(i - 1, p) + kick * n01(rng);
  }
  // Cut-off 6 tau: truncation bias -exp(-6) = -0.25% of tau, while the noise of the integral
  // grows ~ sqrt(cut-off) (relative sd ~ sqrt(2 cut / total time) ~ 0.4% here). Integrating to
  // the first zero crossing alone would wander out to where C ~ its noise (~ 1e-3 sigma^2, i.e.
  // ~ 7 tau) with a random, seed-dependent cut-off; a fixed max_lag bounds both effects.
  const long cut = static_cast<long>(std::lround(6.0 * tau / dt));
  const Autocorrelation ac = velocity_autocorrelation(v, dt, cut);
  const Persistence ps = persistence_time(ac);
  EXPECT_NEAR(ps.c0, sigma * sigma, 0.02 * sigma * sigma);
  EXPECT_NEAR(ps.psi_e, tau, 0.02 * tau);
  EXPECT_NEAR(ps.psi, tau, 0.02 * tau);

  // Positions y_0 = 0, y_{n+1} = y_n + v_n dt, overwriting v.
  for (long p = 0; p < particles; ++p) {
    double v_prev = v(0, p);
    v(0, p) = 0.0;
    for (long i = 1; i < frames; ++i) {
      const double v_cur = v(i, p);
      v(i, p) = v(i - 1, p) + v_prev * dt;
      v_prev = v_cur;
    }
  }
  const Eigen::MatrixXd& y = v;

  // With y_{n+1} = y_n + v_n dt, the long-time MSD slope is 2 dt^2 sum_k C(k dt) / (2 dt) =
  // C(0) dt (1 + r) / (2 (1 - r)), which is exactly C(0) times the trapezoid integral of the
  // sampled exponential: D = dv^2 Psi then holds without discretisation error, leaving only the
  // statistical error (~1% each for the MSD slope and Psi, positively correlated since both
  // measure the integral of C) and the e^-6 truncation of Psi, hence a 3% tolerance.
  // Window [10, 40] tau: MSD = 2 D (t - tau (1 - e^{-t/tau})) is linear there to e^-10.
  const long max_lag = static_cast<long>(std::lround(40.0 * tau / dt));
  const DiffusionFit fd =
      fit_diffusion(mean_square_displacement(y, dt, max_lag), 10.0 * tau, 40.0 * tau);
  const double d_vacf = ps.c0 * ps.psi;
  EXPECT_NEAR(fd.d, d_vacf, 0.03 * d_vacf);
  EXPECT_NEAR(fd.d, sigma * sigma * tau, 0.03 * sigma * sigma * tau);
  // Intercept -2 D tau from the ballistic start; extrapolated from t ~ 25 tau its sd is ~20%,
  // so only its sign is a robust check.
  EXPECT_LT(fd.intercept, 0.0);
  // The log-log slope is not yet 1 here (MSD ~ 2 D (t - tau)): compare with the same fit of the
  // exact OU MSD, 2 sigma^2 tau^2 (t / tau - 1 + e^{-t / tau}).
  MsdResult exact;
  for (long k = 0; k <= max_lag; ++k) {
    const double t = static_cast<double>(k) * dt;
    exact.lag.push_back(t);
    exact.msd.push_back(2.0 * sigma * sigma * tau * tau * (t / tau - 1.0 + std::exp(-t / tau)));
  }
  const double expected_slope = fit_diffusion(exact, 10.0 * tau, 40.0 * tau).loglog_slope;
  EXPECT_GT(expected_slope, 1.03);
  EXPECT_NEAR(fd.loglog_slope, expected_slope, 0.01);
}

TEST(AnalysisPowerLaw, ExactDataIsRecoveredExactly) {
  const std::vector<double> x = logspace(1e-4, 1e-1, 10);
  std::vector<double> g;
  for (double xi : x) g.push_back(0.024 * std::pow(xi, -0.26));
  const PowerLawFit f = fit_power_law(x, g);
  EXPECT_NEAR(f.a, 0.024, 1e-12);
  EXPECT_NEAR(f.b, -0.26, 1e-12);
  EXPECT_LT(f.a_stderr, 1e-12);
  EXPECT_LT(f.b_stderr, 1e-12);
  EXPECT_EQ(f.n, 10);
  EXPECT_NEAR(f.r2, 1.0, 1e-12);
}

PowerLawFit noisy_fit(unsigned seed, double noise) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  const std::vector<double> x = logspace(1e-4, 1e-1, 10);
  std::vector<double> g;
  for (double xi : x) g.push_back(0.024 * std::pow(xi, -0.26) * std::exp(noise * n01(rng)));
  return fit_power_law(x, g);
}

TEST(AnalysisPowerLaw, NoisyDataWithinStandardErrors) {
  const PowerLawFit f = noisy_fit(7, 0.02);
  EXPECT_LT(std::abs(f.a - 0.024), 2.5 * f.a_stderr);
  EXPECT_LT(std::abs(f.b + 0.26), 2.5 * f.b_stderr);
  // Expected se_b = noise / sqrt(Sxx of ln x) ~ 0.02 / sqrt(48.6) ~ 2.9e-3.
  EXPECT_GT(f.b_stderr, 1.5e-3);
  EXPECT_LT(f.b_stderr, 6e-3);
  EXPECT_GT(f.r2, 0.9);
}

// (b - b_true) / se_b is Student-t with n - 2 = 8 dof: P(|t| < 1) = 0.65.
TEST(AnalysisPowerLaw, SlopeStandardErrorIsCalibrated) {
  int inside_b = 0, inside_a = 0;
  const int trials = 200;
  for (int s = 0; s < trials; ++s) {
    const PowerLawFit f = noisy_fit(1000u + static_cast<unsigned>(s), 0.02);
    inside_b += std::abs(f.b + 0.26) < f.b_stderr;
    inside_a += std::abs(f.a - 0.024) < f.a_stderr;
  }
  EXPECT_GT(inside_b, 0.55 * trials);
  EXPECT_LT(inside_b, 0.80 * trials);
  EXPECT_GT(inside_a, 0.55 * trials);
  EXPECT_LT(inside_a, 0.80 * trials);
}

TEST(AnalysisDilatancy, ExactLawIsRecovered) {
  const std::vector<double> j = logspace(1e-4, 1e-1, 10);
  std::vector<double> phi;
  for (double ji : j) phi.push_back(0.81 - 0.64 * std::sqrt(ji));
  const DilatancyFit f = fit_dilatancy(j, phi);
  EXPECT_NEAR(f.phi_c, 0.81, 1e-7);
  EXPECT_NEAR(f.law.a, 0.64, 1e-4);
  EXPECT_NEAR(f.law.b, 0.5, 1e-5);
  EXPECT_LT(f.phi_c_err, 1e-7);
  EXPECT_LT(f.phi_c_stderr, 1e-6);
  EXPECT_LT(f.b_stderr_joint, 1e-5);
}

DilatancyFit noisy_dilatancy(unsigned seed) {
  const std::vector<double> j = logspace(1e-4, 1e-1, 12);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 3e-4);  // small vs the smallest gap 0.0064
  std::vector<double> phi;
  for (double ji : j) phi.push_back(0.81 - 0.64 * std::sqrt(ji) + noise(rng));
  const DilatancyFit f = fit_dilatancy(j, phi);
  EXPECT_GT(f.phi_c, *std::max_element(phi.begin(), phi.end()));
  return f;
}

TEST(AnalysisDilatancy, NoisyLawWithinErrors) {
  const DilatancyFit f = noisy_dilatancy(99);
  EXPECT_NEAR(f.phi_c, 0.81, std::max(3.0 * f.phi_c_err, 0.005));
  EXPECT_NEAR(f.phi_c, 0.81, 3.0 * f.phi_c_stderr);
  // The joint errors: the seed's conditional ones are miscalibrated (next test).
  EXPECT_LT(std::abs(f.law.b - 0.5), 3.0 * f.b_stderr_joint);
  EXPECT_LT(std::abs(f.law.a - 0.64), 3.0 * f.a_stderr_joint);
  EXPECT_GT(f.b_stderr_joint, f.law.b_stderr);
}

// Why the joint errors exist: with phi_c tuned on the same data, the error of b follows phi_c's
// and the conditional stderr covers |b - 0.5| only ~25% of the time at 1 se (measured 23% over
// 400 seeds), ~60% at 3 se; the joint one ~55% and ~98% (the log-space residuals are
// heteroscedastic for additive noise in phi, so even the joint errors run a little small).
TEST(AnalysisDilatancy, JointStandardErrorsCoverTheSlope) {
  int cond1 = 0, joint1 = 0, joint3 = 0;
  const int trials = 200;
  for (int s = 0; s < trials; ++s) {
    const DilatancyFit f = noisy_dilatancy(static_cast<unsigned>(s));
    const double err = std::abs(f.law.b - 0.5);
    cond1 += err < f.law.b_stderr;
    joint1 += err < f.b_stderr_joint;
    joint3 += err < 3.0 * f.b_stderr_joint;
  }
  EXPECT_LT(cond1, 0.40 * trials);
  EXPECT_GT(joint1, 0.45 * trials);
  EXPECT_LT(joint1, 0.80 * trials);
  EXPECT_GT(joint3, 0.93 * trials);
}

// Measured phi(J) (configs/sweep_2core.toml, ktilde = 1e4, docs/results.md): not an exact
// power law, and the log-log residual has a minimum at phi_c ~ 0.81 but falls again towards
// phi_c -> max(phi) + 0.5 (a degenerate b -> 0 fit). The fit must take the first minimum.
TEST(AnalysisDilatancy, MeasuredSweepTakesTheFirstMinimum) {
  const std::vector<double> j = {1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2, 1e-1};
  const std::vector<double> phi = {0.7961, 0.7909, 0.7795, 0.7697, 0.7383, 0.696, 0.6363};
  const DilatancyFit f = fit_dilatancy(j, phi);
  EXPECT_GT(f.phi_c, 0.80);
  EXPECT_LT(f.phi_c, 0.83);
  EXPECT_GT(f.law.b, 0.25);
  EXPECT_LT(f.law.b, 0.6);
}

TEST(AnalysisBadInput, Throws) {
  const std::vector<double> two = {1.0, 2.0}, three = {1.0, 2.0, 3.0};
  EXPECT_THROW(fit_power_law(two, two), std::invalid_argument);
  EXPECT_THROW(fit_power_law(three, two), std::invalid_argument);
  EXPECT_THROW(fit_power_law(three, {1.0, 0.0, 2.0}), std::invalid_argument);
  EXPECT_THROW(fit_power_law({-1.0, 2.0, 3.0}, three), std::invalid_argument);
  EXPECT_THROW(fit_power_law({2.0, 2.0, 2.0}, three), std::invalid_argument);
  EXPECT_THROW(fit_line(three, {1.0, NAN, 2.0}), std::invalid_argument);
  EXPECT_THROW(fit_dilatancy(three, {0.7, 0.6, 0.5}), std::invalid_argument);
  EXPECT_THROW(fit_dilatancy({1.0, 2.0, 3.0, 4.0}, three), std::invalid_argument);
  EXPECT_THROW(fit_dilatancy({0.0, 2.0, 3.0, 4.0}, {0.7, 0.6, 0.5, 0.4}), std::invalid_argument);

  const Eigen::MatrixXd y = random_walks(50, 3, 1.0, 0.1, 0.0, 1);
  EXPECT_THROW(mean_square_displacement(y, 0.1, 50), std::invalid_argument);
  EXPECT_THROW(mean_square_displacement(y, 0.0, 10), std::invalid_argument);
  EXPECT_THROW(mean_square_displacement(y, 0.1, -1), std::invalid_argument);
  EXPECT_THROW(mean_square_displacement(Eigen::MatrixXd(1, 3), 0.1, 0), std::invalid_argument);
  EXPECT_THROW(mean_square_displacement(y, 0.1, 10, {}), std::invalid_argument);
  EXPECT_THROW(mean_square_displacement(y, 0.1, 10, {45}), std::invalid_argument);
  EXPECT_THROW(mean_square_displacement(y, 0.1, 10, {-1}), std::invalid_argument);
  EXPECT_THROW(draw_reference_frames(0, 10, 10, 5, 1), std::invalid_argument);
  EXPECT_THROW(draw_reference_frames(0, 100, 10, 0, 1), std::invalid_argument);
  EXPECT_THROW(velocity_autocorrelation(y, 0.1, 50), std::invalid_argument);

  const MsdResult m = mean_square_displacement(y, 0.1, 10);
  EXPECT_THROW(fit_diffusion(m, 0.25, 0.45), std::invalid_argument);  // 2 lags in window
  EXPECT_THROW(fit_diffusion(m, 0.5, 0.2), std::invalid_argument);
  MsdResult bad = m;
  bad.msd.pop_back();
  EXPECT_THROW(fit_diffusion(bad, 0.1, 1.0), std::invalid_argument);

  Autocorrelation ac{{0.0, 1.0, 2.0}, {0.0, 0.5, 0.2}};
  EXPECT_THROW(persistence_time(ac), std::invalid_argument);  // C(0) = 0
  ac.c = {1.0};
  EXPECT_THROW(persistence_time(ac), std::invalid_argument);
}

}  // namespace
}  // namespace sheardiff
