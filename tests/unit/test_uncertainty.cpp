// The run's own error bars (src/analysis/uncertainty.cpp) against synthetic trajectories whose
// truth is known: the quoted one-sigma interval must cover the truth at about its nominal rate
// (68.3 %). With 150 independent trials the coverage has a binomial standard deviation of 3.8 %,
// so [0.55, 0.82] is a +-3.5 sigma band around the nominal rate; a estimator off by a factor
// 1.5 in its error (coverage 0.85 or 0.48) fails it. The regression error of the MSD fit, which
// treats correlated MSD points as independent, is checked to fail the same test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "sheardiff/analysis/time_series.hpp"
#include "sheardiff/analysis/uncertainty.hpp"

namespace sd = sheardiff;

namespace {

constexpr double kDt = 0.1;    // frame spacing (strain)
constexpr long kFrames = 301;  // 30 strains: the seed's measured window
constexpr long kParticles = 50;
constexpr double kLo = 8.0, kHi = 15.0;  // the seed's MSD window

enum class Walk { brownian, ornstein_uhlenbeck, common_mode };

// Frames x particles of y, and the true D of the process.
std::pair<Eigen::MatrixXd, double> synthetic(Walk kind, std::mt19937_64& rng) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::MatrixXd y = Eigen::MatrixXd::Zero(kFrames, kParticles);
  double d_true = 0;
  if (kind == Walk::brownian || kind == Walk::common_mode) {
    const double d_own = 1.0, d_common = kind == Walk::common_mode ? 0.3 : 0.0;
    for (long t = 1; t < kFrames; ++t) {
      const double shared = std::sqrt(2 * d_common * kDt) * gauss(rng);
      for (long i = 0; i < kParticles; ++i)
        y(t, i) = y(t - 1, i) + std::sqrt(2 * d_own * kDt) * gauss(rng) + shared;
    }
    d_true = d_own + d_common;
  } else {
    // Velocity persistence tau = 0.3 strain (Psi at J ~ 0.1): D = <v^2> tau.
    const double tau = 0.3, a = std::exp(-kDt / tau);
    Eigen::VectorXd v(kParticles);
    for (long i = 0; i < kParticles; ++i) v(i) = gauss(rng);
    for (long t = 1; t < kFrames; ++t)
      for (long i = 0; i < kParticles; ++i) {
        y(t, i) = y(t - 1, i) + v(i) * kDt;
        v(i) = a * v(i) + std::sqrt(1 - a * a) * gauss(rng);
      }
    d_true = tau;
  }
  return {y, d_true};
}

struct Coverage {
  double quoted = 0, regression = 0;
};

Coverage coverage(Walk kind, long block_frames, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const int trials = 150;
  int inside = 0, inside_regression = 0;
  for (int k = 0; k < trials; ++k) {
    const auto [y, d_true] = synthetic(kind, rng);
    const sd::MsdSlopeError e = sd::msd_slope_error(y, kDt, kLo, kHi, block_frames);
    inside += std::abs(e.d - d_true) <= e.err;
    const auto fit = sd::fit_diffusion(
        sd::mean_square_displacement(y, kDt, static_cast<long>(kHi / kDt) + 1), kLo, kHi);
    inside_regression += std::abs(fit.d - d_true) <= fit.d_stderr;
  }
  const Coverage c{inside / static_cast<double>(trials),
                   inside_regression / static_cast<double>(trials)};
  std::printf("coverage of the one-sigma interval: quoted %.3f, regression %.3f\n", c.quoted,
              c.regression);
  return c;
}

}  // namespace

TEST(MsdSlopeError, EstimateIsTheMsdFitOverEveryReferenceTime) {
  std::mt19937_64 rng(3);
  const auto [y, d_true] = synthetic(Walk::brownian, rng);
  (void)d_true;
  const sd::MsdSlopeError e = sd::msd_slope_error(y, kDt, kLo, kHi, 30);
  const auto fit = sd::fit_diffusion(
      sd::mean_square_displacement(y, kDt, static_cast<long>(kHi / kDt) + 1), kLo, kHi);
  EXPECT_NEAR(e.d, fit.d, 1e-9 * std::abs(fit.d));
  EXPECT_EQ(e.blocks, 10);
  EXPECT_GT(e.var_between, 0.0);
  EXPECT_GT(e.var_within, 0.0);
}

TEST(MsdSlopeError, CoversTheTruthOfRandomWalks) {
  const Coverage c = coverage(Walk::brownian, 15, 11);
  EXPECT_GT(c.quoted, 0.55);
  EXPECT_LT(c.quoted, 0.82);
  // The regression error ignores that MSD points share displacements: it covers far less.
  EXPECT_LT(c.regression, 0.35);
}

TEST(MsdSlopeError, CoversTheTruthOfPersistentWalks) {
  // Blocks of 3 strains = 10 persistence times.
  const Coverage c = coverage(Walk::ornstein_uhlenbeck, 30, 12);
  EXPECT_GT(c.quoted, 0.55);
  EXPECT_LT(c.quoted, 0.82);
  EXPECT_LT(c.regression, 0.35);
}

TEST(MsdSlopeError, CoversTheTruthWithCollectiveMotion) {
  // A mode shared by every particle: a particle bootstrap would miss its variance entirely.
  const Coverage c = coverage(Walk::common_mode, 15, 13);
  EXPECT_GT(c.quoted, 0.55);
  EXPECT_LT(c.quoted, 0.82);
  EXPECT_LT(c.regression, 0.35);
}

TEST(PersistenceWithErrors, CoversTheTruthOfOrnsteinUhlenbeckVelocities) {
  // v: OU with tau = 0.3, frames 0.05 apart, 30 strains; Psi (integral to the first zero
  // crossing) = tau (1 - e^-crossing/tau) ~ tau, dv = 1.
  std::mt19937_64 rng(21);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double dt = 0.05, tau = 0.3, a = std::exp(-dt / tau);
  const long frames = 601, particles = 20;
  int psi_inside = 0, dv_inside = 0;
  const int trials = 150;
  for (int k = 0; k < trials; ++k) {
    Eigen::MatrixXd v(frames, particles);
    for (long i = 0; i < particles; ++i) v(0, i) = gauss(rng);
    for (long t = 1; t < frames; ++t)
      for (long i = 0; i < particles; ++i)
        v(t, i) = a * v(t - 1, i) + std::sqrt(1 - a * a) * gauss(rng);
    const sd::PersistenceEstimate e = sd::persistence_with_errors(v, dt, 40, 60);
    psi_inside += std::abs(e.p.psi - tau) <= e.psi_err;
    dv_inside += std::abs(e.dv - 1.0) <= e.dv_err;
  }
  std::printf("coverage: Psi %.3f, dv %.3f\n", psi_inside / double(trials),
              dv_inside / double(trials));
  EXPECT_GT(psi_inside / double(trials), 0.55);
  EXPECT_LT(psi_inside / double(trials), 0.82);
  EXPECT_GT(dv_inside / double(trials), 0.55);
  EXPECT_LT(dv_inside / double(trials), 0.82);
}

TEST(PersistenceWithErrors, MaskSelectsParticles) {
  // Two populations with different persistence; the mask keeps only the second.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double dt = 0.05;
  const long frames = 801, particles = 40;
  Eigen::MatrixXd v(frames, particles), mask = Eigen::MatrixXd::Zero(frames, particles);
  for (long i = 0; i < particles; ++i) {
    const double tau = i < particles / 2 ? 0.1 : 0.5, a = std::exp(-dt / tau);
    v(0, i) = gauss(rng);
    for (long t = 1; t < frames; ++t) v(t, i) = a * v(t - 1, i) + std::sqrt(1 - a * a) * gauss(rng);
    if (i >= particles / 2) mask.col(i).setOnes();
  }
  const auto all = sd::persistence_with_errors(v, dt, 60, 100);
  const auto slow = sd::persistence_with_errors(v, dt, 60, 100, &mask);
  EXPECT_NEAR(slow.p.psi, 0.5, 4 * slow.psi_err + 0.03);
  EXPECT_LT(all.p.psi, slow.p.psi - 0.1);
}

TEST(BatchMeans, StandardErrorOfIndependentBlocks) {
  std::mt19937_64 rng(8);
  std::normal_distribution<double> gauss(2.0, 1.0);
  std::vector<double> t, x;
  for (int k = 0; k < 10000; ++k) t.push_back(k * 0.01), x.push_back(gauss(rng));
  const sd::BatchMeans b = sd::batch_means(t, x, 0.0, 100.0, 10);
  EXPECT_EQ(b.blocks, 10);
  EXPECT_NEAR(b.mean, 2.0, 0.04);
  // sd of the mean of 10000 independent samples: 0.01; batch means estimate it within ~25 %.
  EXPECT_GT(b.err, 0.005);
  EXPECT_LT(b.err, 0.016);
}

namespace {

// AR(1) samples of correlation time tau (in samples) about 2, one in 50 not finite.
std::vector<double> correlated_samples(long n, double tau, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  const double a = std::exp(-1.0 / tau);
  double x = g(rng);
  std::vector<double> out;
  for (long k = 0; k < n; ++k) {
    out.push_back(k % 50 == 7 ? std::nan("") : 2.0 + x);
    x = a * x + std::sqrt(1 - a * a) * g(rng);
  }
  return out;
}

double archived_bytes(sd::BinnedSeries& s) {
  sd::Archive a = sd::Archive::writer();
  s.serialize(a);
  return static_cast<double>(a.bytes().size());
}

}  // namespace

// While every bin holds one sample, the binned batch means are the samples' batch means to the
// bit (mean, error and each block's mean), non-finite samples left out of both alike.
TEST(BinnedSeries, WhileBinsHoldOneSampleTheBatchMeansAreTheSamples) {
  std::mt19937_64 rng(21);
  const auto x = correlated_samples(1500, 10.0, rng);
  std::vector<double> t, y;
  sd::BinnedSeries s(2, 2048);
  for (std::size_t k = 0; k < x.size(); ++k) {
    t.push_back(3.0 + 0.02 * static_cast<double>(k));
    y.push_back(-x[k]);
    s.add(t.back(), {x[k], y.back()});
  }
  ASSERT_EQ(s.samples_per_bin(), 1);
  for (const auto& [signal, values] : {std::pair{std::size_t{0}, x}, std::pair{std::size_t{1}, y}})
    for (long blocks : {4L, 10L, 13L}) {
      const sd::BatchMeans a = sd::batch_means(t, values, 3.0, t.back(), blocks);
      const sd::BatchMeans b = sd::batch_means(s, signal, 3.0, t.back(), blocks);
      EXPECT_EQ(a.mean, b.mean);
      EXPECT_EQ(a.err, b.err);
      EXPECT_EQ(a.block_means, b.block_means);
    }
}

// A run longer than the bins hold: memory stays bounded (bins joined pairwise, at most
// max_bins), every sample is counted, and the batch means stay those of the samples. With 2^17
// samples in 1024 to 2048 bins and 20 blocks, a block holds >= 51 bins; a bin that straddles a
// block boundary moves at most half a bin (< 1 % of the block's samples) across it, so block
// means and their scatter move by ~1 % of the noise: 3 % on the error bounds that.
TEST(BinnedSeries, JoinedBinsKeepMemoryBoundedAndTheBatchMeansClose) {
  std::mt19937_64 rng(22);
  const long n = 1L << 17;
  const auto x = correlated_samples(n, 40.0, rng);
  std::vector<double> t;
  sd::BinnedSeries s(1, 2048);
  double half_size = 0;
  for (long k = 0; k < n; ++k) {
    t.push_back(static_cast<double>(k));
    s.add(t.back(), {x[static_cast<std::size_t>(k)]});
    if (k + 1 == n / 2) half_size = archived_bytes(s);
  }
  EXPECT_EQ(s.samples(), n);
  EXPECT_LE(s.bins(), 2048u);
  EXPECT_GE(s.bins(), 1024u);
  EXPECT_EQ(s.samples_per_bin(), 64);
  // 2048 bins of (count, time, sum, finite count) at most, whatever the run's length.
  EXPECT_LE(archived_bytes(s), 2048.0 * 4 * 8 + 200);
  EXPECT_LE(archived_bytes(s), half_size + 200) << "it does not grow with the run";
  const sd::BatchMeans a = sd::batch_means(t, x, 0.0, t.back(), 20);
  const sd::BatchMeans b = sd::batch_means(s, 0, 0.0, t.back(), 20);
  EXPECT_NEAR(b.mean, a.mean, 1e-12);
  ASSERT_EQ(b.blocks, 20);
  EXPECT_NEAR(b.err, a.err, 0.03 * a.err);
  double shift = 0;
  for (std::size_t k = 0; k < 20; ++k) {
    EXPECT_NEAR(b.block_means[k], a.block_means[k], 0.02);
    shift = std::max(shift, std::abs(b.block_means[k] - a.block_means[k]));
  }
  std::printf("binned against sampled: error %+.2f %%, largest block-mean shift %.4f (noise 1)\n",
              100.0 * (b.err / a.err - 1.0), shift);
}

// What a checkpoint carries is the series: saved, loaded and continued, it equals the one that
// ran through.
TEST(BinnedSeries, SavedAndLoadedItContinuesAsIfUninterrupted) {
  std::mt19937_64 rng(23);
  const auto x = correlated_samples(5000, 5.0, rng);
  sd::BinnedSeries whole(1, 256), first(1, 256);
  for (std::size_t k = 0; k < 3000; ++k)
    whole.add(static_cast<double>(k), {x[k]}), first.add(static_cast<double>(k), {x[k]});
  sd::Archive out = sd::Archive::writer();
  first.serialize(out);
  sd::BinnedSeries resumed;
  sd::Archive in = sd::Archive::reader(out.bytes());
  resumed.serialize(in);
  EXPECT_TRUE(in.at_end());
  for (std::size_t k = 3000; k < x.size(); ++k)
    whole.add(static_cast<double>(k), {x[k]}), resumed.add(static_cast<double>(k), {x[k]});
  const sd::BatchMeans a = sd::batch_means(whole, 0, 0.0, 4999.0, 8);
  const sd::BatchMeans b = sd::batch_means(resumed, 0, 0.0, 4999.0, 8);
  EXPECT_EQ(a.mean, b.mean);
  EXPECT_EQ(a.err, b.err);
  EXPECT_EQ(resumed.bins(), whole.bins());
}
