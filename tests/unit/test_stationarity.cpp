// The steady-state window test (src/analysis/stationarity.cpp) on synthetic series whose truth is
// known. A stationary AR(1) series (correlation time 0.5 strain, well inside the 3-strain error
// blocks of a 30-strain window) must pass at z = 3 in all but a few per cent of trials: with 10
// blocks the statistic is close to Student's t with 9 (mean) or 8 (trend) degrees of freedom,
// whose two-sided tail beyond 3 is 1.5-1.7 %; 400 trials give a binomial sd of 0.6 %, so a rate
// above 5 % means the errors are underestimated by about a third. A drift whose effect is six
// errors must be caught in at least 90 % of trials (the t statistic's power there is > 98 %).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sheardiff/analysis/power_law.hpp"
#include "sheardiff/analysis/stationarity.hpp"
#include "sheardiff/observe/pressure_cell.hpp"

namespace sd = sheardiff;

namespace {

constexpr double kDt = 0.02, kFrom = 3.0, kTo = 33.0;  // frames, the measured window (strain)
constexpr long kBlocks = 10;                           // of 3 strain, as analysis.error_block
constexpr int kTrials = 400;

std::vector<double> times() {
  std::vector<double> t;
  for (double s = kFrom; s <= kTo + 1e-9; s += kDt) t.push_back(s);
  return t;
}

// Unit-variance AR(1) noise of correlation time tau (strain) plus drift * (t - kFrom) + offset.
std::vector<double> series(const std::vector<double>& t, double tau, double offset, double drift,
                           std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  const double a = std::exp(-kDt / tau);
  double x = g(rng);
  std::vector<double> out;
  for (double s : t) {
    out.push_back(x + offset + drift * (s - kFrom));
    x = a * x + std::sqrt(1 - a * a) * g(rng);
  }
  return out;
}

// The error of a 30-strain mean of that noise: sqrt(2 tau / T) for tau << T.
double mean_error(double tau) {
  return std::sqrt(2.0 * tau / (kTo - kFrom));
}

}  // namespace

TEST(Stationarity, StationaryNoiseRarelyFlagged) {
  std::mt19937_64 rng(11);
  const auto t = times();
  int mean_flags = 0, trend_flags = 0;
  for (int k = 0; k < kTrials; ++k) {
    const auto x = series(t, 0.5, 0.0, 0.0, rng);
    mean_flags += !sd::mean_within_noise("x", t, x, 0.0, kFrom, kTo, kBlocks, 3.0).ok;
    trend_flags += !sd::trend_within_noise("x", t, x, kFrom, kTo, kBlocks, 3.0).ok;
  }
  EXPECT_LT(mean_flags, 0.05 * kTrials);
  EXPECT_LT(trend_flags, 0.05 * kTrials);
  // And not a test that never flags anything: some false alarms are expected (1.5 % of 400 = 6).
  EXPECT_GT(mean_flags + trend_flags, 0);
}

TEST(Stationarity, OffsetAndDriftOfSixErrorsCaught) {
  std::mt19937_64 rng(12);
  const auto t = times();
  const double e = mean_error(0.5);
  int offset_caught = 0, drift_caught = 0;
  for (int k = 0; k < kTrials; ++k) {
    const auto off = series(t, 0.5, 6.0 * e, 0.0, rng);
    offset_caught += !sd::mean_within_noise("x", t, off, 0.0, kFrom, kTo, kBlocks, 3.0).ok;
    // The OLS line through n block means (each with error e sqrt(n)) has a change across the
    // window with error e n sqrt(12 / (n^2 - 1)); a drift of 6 such errors:
    const double change_err = e * kBlocks * std::sqrt(12.0 / (kBlocks * kBlocks - 1.0));
    const auto drifting = series(t, 0.5, 0.0, 6.0 * change_err / (kTo - kFrom), rng);
    drift_caught += !sd::trend_within_noise("x", t, drifting, kFrom, kTo, kBlocks, 3.0).ok;
  }
  EXPECT_GT(offset_caught, 0.9 * kTrials);
  EXPECT_GT(drift_caught, 0.9 * kTrials);
}

TEST(Stationarity, ToleranceIsAbsolute) {
  std::mt19937_64 rng(13);
  const auto t = times();
  const auto near = series(t, 0.5, 1.03, 0.0, rng);
  const auto far = series(t, 0.5, 1.07, 0.0, rng);
  // The noise is 1 P here and its window error ~0.18: an absolute tolerance of 0.05 P ignores it
  // only where the mean is far from the bound; shrink the noise so the means are sharp.
  std::vector<double> a, b;
  for (std::size_t k = 0; k < t.size(); ++k)
    a.push_back(1.03 + 0.01 * (near[k] - 1.03)), b.push_back(1.07 + 0.01 * (far[k] - 1.07));
  const auto pass = sd::mean_within_tolerance("load", t, a, 1.0, kFrom, kTo, kBlocks, 0.05);
  const auto fail = sd::mean_within_tolerance("load", t, b, 1.0, kFrom, kTo, kBlocks, 0.05);
  EXPECT_TRUE(pass.ok);
  // The window error of these means is 0.0018: 0.006 is 3.3 of it.
  EXPECT_NEAR(pass.value, 0.03, 0.006);
  EXPECT_FALSE(fail.ok);
  EXPECT_NEAR(fail.value, 0.07, 0.006);
}

TEST(Stationarity, TooShortWindowIsNotStationary) {
  const std::vector<double> t = {0.0, 0.1, 0.2}, x = {1.0, 1.0, 1.0};
  // Three blocks cannot give a trend with its own error.
  EXPECT_FALSE(sd::trend_within_noise("x", t, x, 0.0, 0.2, 3, 3.0).ok);
  EXPECT_FALSE(sd::StationarityVerdict{}.stationary());
}

// The pressure cell's verdict names the signal that drifted: a dilation's drag on the discs
// (mean 0.05 P against a window error of ~0.01) with mu, H and the bulk load steady.
TEST(Stationarity, PressureCellNamesTheDriftingSignal) {
  std::mt19937_64 rng(14);
  const auto t = times();
  auto scaled = [&](double level, double noise, double drift) {
    auto x = series(t, 0.5, 0.0, 0.0, rng);
    for (std::size_t k = 0; k < x.size(); ++k) x[k] = level + noise * x[k] + drift * (t[k] - kFrom);
    return x;
  };
  const auto h = scaled(40.0, 0.3, 0.0), top = scaled(0.5, 0.05, 0.0);
  const auto bottom = scaled(0.5, 0.05, 0.0), load = scaled(1.0, 0.05, 0.0);
  sd::SteadyStateParams cfg;
  const auto still = scaled(0.0, 0.05, 0.0), sinking = scaled(0.05, 0.05, 0.0);
  const auto verdict = [&](const std::vector<double>& height, const std::vector<double>& drag) {
    const sd::BinnedSeries w = sd::cell_window(t, height, {}, top, bottom, drag, load, kFrom, kTo);
    return sd::pressure_cell_stationarity(cfg, w, kFrom, kTo, 3.0);
  };
  const auto ok = verdict(h, still);
  const auto bad = verdict(h, sinking);
  EXPECT_TRUE(ok.stationary()) << ok.failed();
  EXPECT_FALSE(bad.stationary());
  EXPECT_EQ(bad.failed(), "net_drag_y");
  // A wall that keeps falling 0.09 d per strain (2.7 d over the window, the H noise 0.3 d).
  const auto falling = scaled(40.0, 0.3, -0.09);
  const auto fell = verdict(falling, still);
  EXPECT_EQ(fell.failed(), "H_change");
  EXPECT_NEAR(fell.signals[2].value, -2.7, 0.5);
}

// A checkpoint of layout 6 kept every frame's sample of the window; this version bins them
// (BinnedSeries), so a run checkpointed by the older sheardiff resumes: its samples are binned
// on reading exactly as cell_window bins the same frames, and the state then saves and loads in
// today's layout unchanged.
TEST(Stationarity, PressureCellWindowOfLayoutSixIsBinnedOnReading) {
  std::mt19937_64 rng(15);
  const auto t = times();
  const auto h = series(t, 0.5, 40.0, 0.0, rng), phi = series(t, 0.5, 0.8, 0.0, rng);
  const auto top = series(t, 0.5, 0.5, 0.0, rng), bottom = series(t, 0.5, 0.5, 0.0, rng);
  const auto drag = series(t, 0.5, 0.0, 0.0, rng), load = series(t, 0.5, 1.0, 0.0, rng);
  // The layout-6 section: tag, the detector's history, ten scalars, the free-fall count, then
  // the window's seven frame series.
  sd::Archive old = sd::Archive::writer();
  old.tag("pressure_cell");
  std::vector<double> hist = {0.5, 1.0};
  for (int k = 0; k < 3; ++k) old.io(hist);
  for (double x : {kFrom, kFrom - 10.0, 30.0, 40.0, 0.8, 0.64, 0.5, 0.5, 1.0, 0.01}) old.io(x);
  long free_fall = 0;
  old.io(free_fall);
  for (auto v : {t, h, phi, top, bottom, drag, load}) old.io(v);
  sd::PressureCellObserverOf<sd::Dim2> cell(sd::Config{});
  sd::Archive in = sd::Archive::reader(old.bytes(), 6);
  cell.serialize(in);
  EXPECT_TRUE(in.at_end());
  const sd::BinnedSeries expected = sd::cell_window(t, h, phi, top, bottom, drag, load, kFrom, kTo);
  ASSERT_EQ(cell.window().samples(), static_cast<long>(t.size()));
  for (std::size_t s = 0; s < sd::CellSignal::count; ++s) {
    const sd::BatchMeans a = sd::batch_means(expected, s, kFrom, t.back(), kBlocks);
    const sd::BatchMeans b = sd::batch_means(cell.window(), s, kFrom, t.back(), kBlocks);
    EXPECT_EQ(a.mean, b.mean) << "signal " << s;
    EXPECT_EQ(a.err, b.err) << "signal " << s;
  }
  sd::Archive now = sd::Archive::writer();
  cell.serialize(now);
  sd::PressureCellObserverOf<sd::Dim2> again(sd::Config{});
  sd::Archive back = sd::Archive::reader(now.bytes());
  again.serialize(back);
  EXPECT_TRUE(back.at_end());
  EXPECT_EQ(again.window().samples(), cell.window().samples());
  EXPECT_EQ(sd::batch_means(again.window(), sd::CellSignal::mu, kFrom, t.back(), kBlocks).err,
            sd::batch_means(cell.window(), sd::CellSignal::mu, kFrom, t.back(), kBlocks).err);
}

// window_blocks shows what the verdict weighed: a noiseless H that rises 0.1 d per strain gives
// block means on the line at the blocks' midpoints (a block mean of a linear signal sampled
// evenly is its value at the blocks' mean frame time, within a frame's rise of the midpoint's:
// 0.002 d), and the least-squares line through them is H_change; a signal the run did not record
// is null, not shifted.
TEST(Stationarity, WindowBlocksAreTheMeansTheVerdictUses) {
  const auto t = times();
  std::vector<double> h, top, bottom, drag, load;
  for (double s : t) {
    h.push_back(40.0 + 0.1 * (s - kFrom));
    top.push_back(0.6), bottom.push_back(0.4), drag.push_back(0.0), load.push_back(1.0);
  }
  const sd::BinnedSeries w = sd::cell_window(t, h, {}, top, bottom, drag, load, kFrom, kTo);
  nlohmann::json js;
  sd::add_window_blocks(js, w, kFrom, kTo, 3.0);
  const auto& b = js.at("window_blocks");
  ASSERT_EQ(b.at("strain").size(), static_cast<std::size_t>(kBlocks));
  ASSERT_EQ(b.at("H").size(), static_cast<std::size_t>(kBlocks));
  for (std::size_t k = 0; k < static_cast<std::size_t>(kBlocks); ++k) {
    const double mid = kFrom + (static_cast<double>(k) + 0.5) * 3.0;
    EXPECT_NEAR(b.at("strain")[k].get<double>(), mid, 1e-12);
    EXPECT_NEAR(b.at("H")[k].get<double>(), 40.0 + 0.1 * (mid - kFrom), 2e-3) << k;
    EXPECT_NEAR(b.at("mu")[k].get<double>(), 0.5, 1e-12);
    EXPECT_NEAR(b.at("mu_top_minus_bottom")[k].get<double>(), 0.2, 1e-12);
    EXPECT_NEAR(b.at("bulk_normal_load")[k].get<double>(), 1.0, 1e-12);
  }
  EXPECT_TRUE(b.at("phi").is_null());
  const auto v = sd::pressure_cell_stationarity(sd::SteadyStateParams{}, w, kFrom, kTo, 3.0);
  const double slope =
      sd::fit_line(b.at("strain").get<std::vector<double>>(), b.at("H").get<std::vector<double>>())
          .slope;
  EXPECT_NEAR(v.signals[2].value, slope * (kTo - kFrom), 1e-9);
  EXPECT_NEAR(v.signals[2].value, 3.0, 0.01);  // 0.1 d per strain over 30 strains
  // A window that is not a whole number of blocks (29 strain: 9 blocks of 29/9) and one of 1
  // strain (at least 4 blocks, here of 0.25): the midpoints follow the blocks' own width.
  for (const double to : {32.0, kFrom + 1.0}) {
    const sd::BinnedSeries part = sd::cell_window(t, h, {}, top, bottom, drag, load, kFrom, to);
    nlohmann::json pj;
    sd::add_window_blocks(pj, part, kFrom, to, 3.0);
    const auto& pb = pj.at("window_blocks");
    const std::size_t n = to == 32.0 ? 9 : 4;
    const double width = (to - kFrom) / static_cast<double>(n);
    ASSERT_EQ(pb.at("strain").size(), n) << to;
    ASSERT_EQ(pb.at("H").size(), n) << to;
    for (std::size_t k = 0; k < n; ++k) {
      const double mid = kFrom + (static_cast<double>(k) + 0.5) * width;
      EXPECT_NEAR(pb.at("strain")[k].get<double>(), mid, 1e-12) << to;
      EXPECT_NEAR(pb.at("H")[k].get<double>(), 40.0 + 0.1 * (mid - kFrom), 2e-3) << to << " " << k;
    }
  }
  // Too short a window: no blocks (as no error bars).
  nlohmann::json none;
  const sd::BinnedSeries few =
      sd::cell_window(t, h, {}, top, bottom, drag, load, kFrom, kFrom + 0.1);
  sd::add_window_blocks(none, few, kFrom, kFrom + 0.1, 3.0);
  EXPECT_FALSE(none.contains("window_blocks"));
}
