// The diffusion analysis accumulated during the run (MultipleTauCorrelator, IncrementGram,
// DiffusionAccumulator) against the frame analysis of the same samples (time_series.hpp,
// uncertainty.hpp): equal to round-off, and its checkpoint small whatever the window's length.
// Round-off: the frame functions sum by FFT or in other orders; 1e-10 relative is ~1e5 ulps,
// far below any statistical error and far above what summation order can change here.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sheardiff/analysis/correlator.hpp"
#include "sheardiff/analysis/diffusion.hpp"
#include "sheardiff/analysis/time_series.hpp"
#include "sheardiff/analysis/uncertainty.hpp"

namespace sd = sheardiff;
using Kind = sd::MultipleTauCorrelator::Kind;

namespace {

constexpr double kRel = 1e-10;

// Persistent walks (velocity correlation time tau samples): v (frames x particles) and y, its
// running sum, so both signals have structure at every level of the grid.
struct Walks {
  Eigen::MatrixXd y, v;
};
Walks walks(long frames, long particles, double tau, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double a = std::exp(-1.0 / tau);
  Walks w{Eigen::MatrixXd::Zero(frames, particles), Eigen::MatrixXd::Zero(frames, particles)};
  for (long i = 0; i < particles; ++i) w.v(0, i) = gauss(rng);
  for (long t = 1; t < frames; ++t)
    for (long i = 0; i < particles; ++i) {
      w.v(t, i) = a * w.v(t - 1, i) + std::sqrt(1 - a * a) * gauss(rng);
      w.y(t, i) = w.y(t - 1, i) + w.v(t, i);
    }
  return w;
}

Eigen::MatrixXd every(const Eigen::MatrixXd& x, long stride) {
  Eigen::MatrixXd out((x.rows() - 1) / stride + 1, x.cols());
  for (Eigen::Index k = 0; k < out.rows(); ++k) out.row(k) = x.row(k * stride);
  return out;
}

template <class F>
void feed(sd::MultipleTauCorrelator& c, const Eigen::MatrixXd& x, F mask_of) {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor r = x;
  for (Eigen::Index t = 0; t < r.rows(); ++t) c.add(r.row(t).data(), mask_of(t));
}

// Every origin's sums over blocks: the correlation at lag index j.
double total(const sd::MultipleTauCorrelator& c, std::size_t j, bool masked = false) {
  double s = 0, n = 0;
  for (long b = 0; b < c.blocks(); ++b) s += c.sum(b, j, masked), n += c.count(b, j, masked);
  return s / n;
}

}  // namespace

// Level l of the grid is the every-origin analysis of the samples subsampled by 2^l: the VACF
// as velocity_autocorrelation, the MSD as mean_square_displacement, lag by lag.
TEST(MultipleTauCorrelator, EachLevelEqualsTheFrameAnalysisOfItsSubsampledSeries) {
  const Walks w = walks(1500, 7, 20.0, 1);
  sd::MultipleTauCorrelator vacf(Kind::product, 7, 1000, 50, false, 8);
  sd::MultipleTauCorrelator msd(Kind::squared_difference, 7, 1000, 50, false, 8);
  feed(vacf, w.v, [](Eigen::Index) { return nullptr; });
  feed(msd, w.y, [](Eigen::Index) { return nullptr; });
  ASSERT_EQ(vacf.samples(), 1500);
  const auto& lags = vacf.lags();
  EXPECT_EQ(lags.front(), 0);
  EXPECT_LE(lags.back(), 1000);
  EXPECT_GT(lags.back(), 500);  // the grid reaches max_lag's octave
  int checked_levels = 0;
  for (int level = 0; (7L << level) <= 1000; ++level) {
    const long stride = 1L << level;
    const Eigen::MatrixXd v = every(w.v, stride), y = every(w.y, stride);
    const auto c = sd::velocity_autocorrelation(v, 1.0, 7);
    const auto m = sd::mean_square_displacement(y, 1.0, 7);
    for (long k = level == 0 ? 0 : 4; k < 8; ++k) {
      const auto it = std::find(lags.begin(), lags.end(), k * stride);
      ASSERT_NE(it, lags.end()) << "lag " << k * stride;
      const auto j = static_cast<std::size_t>(it - lags.begin());
      const auto kk = static_cast<std::size_t>(k);
      EXPECT_NEAR(total(vacf, j), c.c[kk], kRel * std::abs(c.c[0])) << "level " << level;
      EXPECT_NEAR(total(msd, j), m.msd[kk], kRel * m.msd[7]) << "level " << level;
    }
    ++checked_levels;
  }
  EXPECT_GE(checked_levels, 7);
}

// The masked sums count an origin only where its mask byte is set, as the frame analysis with a
// bulk mask does (masked_mean_square_displacement over every origin).
TEST(MultipleTauCorrelator, MaskedSumsCountOnlyMaskedOrigins) {
  const Walks w = walks(300, 5, 10.0, 2);
  Eigen::MatrixXd mask(300, 5);
  std::vector<std::vector<std::uint8_t>> bytes(300, std::vector<std::uint8_t>(5));
  for (long t = 0; t < 300; ++t)
    for (long i = 0; i < 5; ++i) {
      bytes[t][i] = ((t / 37 + i) % 3 != 0) ? 1 : 0;
      mask(t, i) = bytes[t][i];
    }
  sd::MultipleTauCorrelator msd(Kind::squared_difference, 5, 15, 1000, true, 16);
  feed(msd, w.y, [&](Eigen::Index t) { return bytes[static_cast<std::size_t>(t)].data(); });
  // Every origin with a partner at the longest lag, as the frame function wants them.
  for (long k = 1; k <= 15; ++k) {
    std::vector<long> t0;
    for (long t = 0; t + k < 300; ++t) t0.push_back(t);
    const auto ref = sd::masked_mean_square_displacement(w.y, mask, 1.0, k, t0);
    EXPECT_NEAR(total(msd, static_cast<std::size_t>(k), true), ref.msd[static_cast<std::size_t>(k)],
                kRel * ref.msd[static_cast<std::size_t>(k)]);
  }
}

// A checkpoint in the middle of the window: the accumulator saved, restored into a new one and
// continued gives the numbers of one that never stopped, to the bit.
TEST(MultipleTauCorrelator, SaveAndRestoreMidWayIsBitIdentical) {
  const Walks w = walks(700, 4, 15.0, 3);
  sd::DiffusionSettings s;
  s.window_lo = 40, s.window_hi = 80, s.vacf_max_lag = 100, s.error_block = 60, s.coarse_strain = 4;
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor y = w.y, v = w.v;
  sd::DiffusionAccumulator whole(s, 1.0, 4, false, false), first(s, 1.0, 4, false, false);
  for (long t = 0; t < 700; ++t) whole.add(y.row(t).data(), v.row(t).data());
  for (long t = 0; t < 333; ++t) first.add(y.row(t).data(), v.row(t).data());
  sd::Archive out = sd::Archive::writer();
  first.serialize(out);
  sd::DiffusionAccumulator second(s, 1.0, 4, false, false);
  sd::Archive in = sd::Archive::reader(out.bytes());
  second.serialize(in);
  EXPECT_TRUE(in.at_end());
  for (long t = 333; t < 700; ++t) second.add(y.row(t).data(), v.row(t).data());
  const sd::DiffusionReport a = whole.report(), b = second.report();
  EXPECT_EQ(a.fit.d, b.fit.d);
  EXPECT_EQ(a.d_error.err, b.d_error.err);
  EXPECT_EQ(a.persistence.psi, b.persistence.psi);
  EXPECT_EQ(a.vel.psi_err, b.vel.psi_err);
  EXPECT_EQ(a.msd.msd, b.msd.msd);
  // A restore into an accumulator of another shape is refused, not misread.
  sd::DiffusionSettings other = s;
  other.window_hi = 90;
  sd::DiffusionAccumulator wrong(other, 1.0, 4, false, false);
  sd::Archive again = sd::Archive::reader(out.bytes());
  EXPECT_THROW(wrong.serialize(again), std::runtime_error);
}

// The increment products on coarse samples give msd_slope_error's D, its error bar and the
// every-origin MSD of the same series.
TEST(IncrementGram, GivesTheFrameEstimatorOfDAndItsError) {
  const Walks w = walks(301, 30, 3.0, 4);
  sd::IncrementGram g(30, 160);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor y = w.y;
  for (long t = 0; t < 301; ++t) g.add(y.row(t).data());
  const double dt = 0.1;
  for (long block : {30L, 45L}) {
    const auto ref = sd::msd_slope_error(w.y, dt, 8.0, 15.0, block);
    const auto got = sd::msd_slope_error(g, dt, 8.0, 15.0, block);
    EXPECT_NEAR(got.d, ref.d, kRel * ref.d);
    EXPECT_NEAR(got.err, ref.err, kRel * ref.err);
    EXPECT_EQ(got.blocks, ref.blocks);
  }
  const auto ref = sd::mean_square_displacement(w.y, dt, 150);
  const auto got = g.msd(dt, 150);
  for (std::size_t k = 1; k <= 150; ++k) EXPECT_NEAR(got.msd[k], ref.msd[k], 1e-9 * ref.msd[k]);
  // A window longer than the band cannot be estimated from it: refused.
  EXPECT_THROW(sd::msd_slope_error(g, dt, 8.0, 17.0, 30), std::invalid_argument);
}

// With one level covering every lag, dv, Psi and their jackknife errors are those of
// persistence_with_errors on the same samples and blocks.
TEST(DiffusionAccumulator, PersistenceEqualsTheFrameJackknife) {
  const Walks w = walks(2000, 12, 8.0, 5);
  sd::DiffusionSettings s;
  s.window_lo = 100, s.window_hi = 200, s.vacf_max_lag = 12, s.error_block = 400;
  s.coarse_strain = 10;
  const sd::DiffusionReport r = sd::analyse_diffusion(w.y, w.v, 1.0, s);
  // error_block 400 samples in parts of 25: 80 parts, blocks of 16 parts.
  const auto ref = sd::persistence_with_errors(w.v, 1.0, 12, 400);
  EXPECT_EQ(r.vel.blocks, ref.blocks);
  EXPECT_NEAR(r.dv, ref.dv, kRel * ref.dv);
  EXPECT_NEAR(r.persistence.psi, ref.p.psi, kRel * ref.p.psi);
  EXPECT_NEAR(r.vel.psi_err, ref.psi_err, 1e-8 * ref.psi_err);
  EXPECT_NEAR(r.vel.dv_err, ref.dv_err, 1e-8 * ref.dv_err);
  EXPECT_NEAR(r.persistence.psi_e, ref.p.psi_e, kRel * ref.p.psi_e);
  // The fine MSD grid holds the coarse MSD's lags too: the same numbers.
  const auto it = std::find(r.msd.lag.begin(), r.msd.lag.end(), 160.0);
  ASSERT_NE(it, r.msd.lag.end());
  const auto jc = std::find(r.msd_coarse.lag.begin(), r.msd_coarse.lag.end(), 160.0);
  ASSERT_NE(jc, r.msd_coarse.lag.end());
  // Both are every-origin MSDs, but the fine grid's origins at lag 160 are every 16th sample
  // (level 4), the coarse one's every 10th: equal within the statistics, not to round-off.
  EXPECT_NEAR(*(r.msd.msd.begin() + (it - r.msd.lag.begin())),
              *(r.msd_coarse.msd.begin() + (jc - r.msd_coarse.lag.begin())),
              0.1 * *(r.msd_coarse.msd.begin() + (jc - r.msd_coarse.lag.begin())));
}

// The N = 1000 point at J = 1e-4 with the defaults (samples 3.5e-4 strain apart, MSD to 15
// strains, VACF to 2, coarse samples 0.2 apart): the accumulator's state is what a checkpoint
// carries of the analysis. It must stay far below 5 MB over the sweep's 30 measured strains and
// grow by a few kB per strain (so a 5 MB checkpoint would need hundreds of strains more).
TEST(DiffusionAccumulator, CheckpointSizeStaysSmallAtNThousand) {
  sd::DiffusionSettings s;  // window [8, 15], VACF 2, blocks of 3, coarse 0.2
  const double dt = 3.5e-4;
  const long n = 1000;
  sd::DiffusionAccumulator acc(s, dt, n, true, true);
  std::vector<double> y(n, 0.0), v(n, 0.0), x(n, 0.0);
  std::vector<std::uint8_t> bulk(n, 1);
  std::mt19937_64 rng(6);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const auto size_now = [&] {
    sd::Archive a = sd::Archive::writer();
    acc.serialize(a);
    return static_cast<double>(a.bytes().size());
  };
  double at15 = 0;
  const long per_strain = std::lround(1.0 / dt);
  for (long t = 0; t < 30 * per_strain; ++t) {
    for (long i = 0; i < n; i += 97) v[i] = gauss(rng), y[i] += v[i] * dt, x[i] += gauss(rng) * dt;
    acc.add(y.data(), v.data(), x.data(), bulk.data());
    if (t + 1 == 15 * per_strain) at15 = size_now();
  }
  const double at30 = size_now();
  RecordProperty("bytes_at_30_strains", std::to_string(at30));
  EXPECT_LT(at30, 4.0e6) << "the accumulator alone, leaving room for the run's state";
  const double per_strain_growth = (at30 - at15) / 15.0;
  EXPECT_LT(per_strain_growth, 5.0e3) << per_strain_growth << " bytes per strain";
  std::printf("accumulator at N = 1000, J = 1e-4: %.2f MB after 30 strains, %.1f kB per strain\n",
              at30 / 1e6, per_strain_growth / 1e3);
}

// The displacement velocity u = (y(t) - y(t - Delta)) / Delta, sampled on the MSD's grid: dv and
// Psi equal those of the frame functions on the same u, and Delta is rounded to that grid
// (k 2^l samples, k <= 15). Longer intervals average the velocity: dv falls with Delta while
// dv^2 Psi (the diffusivity the VACF carries) stays close.
TEST(DiffusionAccumulator, DisplacementVelocitiesEqualTheFrameAnalysis) {
  const Walks w = walks(4000, 20, 12.0, 7);
  sd::DiffusionSettings s;
  s.window_lo = 100, s.window_hi = 300, s.vacf_max_lag = 120, s.error_block = 400;
  s.coarse_strain = 10;
  s.velocity_intervals = {3.0, 40.0, 44.0};  // 3 samples; 40 = 10 x 4; 44 -> 11 x 4
  const sd::DiffusionReport r = sd::analyse_diffusion(w.y, w.v, 1.0, s);
  ASSERT_EQ(r.intervals.size(), 3u);
  EXPECT_EQ(r.intervals[0].interval, 3.0);
  EXPECT_EQ(r.intervals[1].interval, 40.0);
  EXPECT_EQ(r.intervals[2].interval, 44.0);
  for (const auto& iv : r.intervals) {
    const long stride = std::lround(iv.sample_strain), k = std::lround(iv.interval) / stride;
    const Eigen::MatrixXd y = every(w.y, stride);
    const Eigen::MatrixXd u = (y.bottomRows(y.rows() - k) - y.topRows(y.rows() - k)) / iv.interval;
    const long lag = std::lround(std::ceil(120.0 / iv.sample_strain));
    // The same lags the grid has, from the every-origin VACF of u.
    const auto c = sd::velocity_autocorrelation(u, iv.sample_strain, std::min(lag, 15L));
    EXPECT_NEAR(iv.vel.dv, std::sqrt(c.c[0]), kRel * std::sqrt(c.c[0]));
    for (std::size_t j = 0; j < 16 && j < iv.vel.c.c.size(); ++j)
      EXPECT_NEAR(iv.vel.c.c[j], c.c[j], kRel * c.c[0]) << "lag " << j;
    EXPECT_TRUE(std::isfinite(iv.vel.psi_err));
  }
  EXPECT_LT(r.intervals[1].vel.dv, r.dv);
  EXPECT_LT(r.intervals[2].vel.dv, r.intervals[1].vel.dv);
  const double d_inst = r.dv * r.dv * r.persistence.psi;
  const double d_40 = std::pow(r.intervals[1].vel.dv, 2) * r.intervals[1].vel.p.psi;
  EXPECT_NEAR(d_40, d_inst, 0.15 * d_inst);
}
