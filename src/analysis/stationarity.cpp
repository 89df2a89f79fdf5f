#include "sheardiff/analysis/stationarity.hpp"

#include <cmath>
#include <limits>

#include "sheardiff/analysis/power_law.hpp"
#include "sheardiff/analysis/uncertainty.hpp"

namespace sheardiff {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

DriftSignal judged(const std::string& name, double value, double err, double limit,
                   double expected = 0.0) {
  DriftSignal s{name, value, expected, err, limit, false};
  s.ok = std::isfinite(value) && std::isfinite(err) && std::isfinite(limit) &&
         std::abs(value) <= limit;
  return s;
}

}  // namespace

DriftSignal mean_within_noise(const std::string& name, const BatchMeans& b, double expected,
                              double z) {
  return judged(name, b.mean - expected, b.err, z * b.err, expected);
}

DriftSignal mean_within_tolerance(const std::string& name, const BatchMeans& b, double expected,
                                  double tolerance) {
  DriftSignal s = judged(name, b.mean - expected, b.err, tolerance, expected);
  s.ok = std::isfinite(b.mean) && std::abs(b.mean - expected) <= tolerance;
  return s;
}

DriftSignal trend_within_noise(const std::string& name, const BatchMeans& b, double from, double to,
                               long blocks, double z) {
  if (b.blocks != blocks || blocks < 4) return judged(name, kNaN, kNaN, kNaN);
  // Block midpoints; the fit's slope error uses the block means' own scatter about the line.
  std::vector<double> mid(static_cast<std::size_t>(blocks));
  const double width = (to - from) / static_cast<double>(blocks);
  for (long k = 0; k < blocks; ++k)
    mid[static_cast<std::size_t>(k)] = from + (static_cast<double>(k) + 0.5) * width;
  const LineFit f = fit_line(mid, b.block_means);
  const double span = to - from;
  return judged(name, f.slope * span, f.slope_stderr * span, z * f.slope_stderr * span);
}

DriftSignal mean_within_noise(const std::string& name, const std::vector<double>& t,
                              const std::vector<double>& x, double expected, double from, double to,
                              long blocks, double z) {
  return mean_within_noise(name, batch_means(t, x, from, to, blocks), expected, z);
}

DriftSignal mean_within_tolerance(const std::string& name, const std::vector<double>& t,
                                  const std::vector<double>& x, double expected, double from,
                                  double to, long blocks, double tolerance) {
  return mean_within_tolerance(name, batch_means(t, x, from, to, blocks), expected, tolerance);
}

DriftSignal trend_within_noise(const std::string& name, const std::vector<double>& t,
                               const std::vector<double>& x, double from, double to, long blocks,
                               double z) {
  return trend_within_noise(name, batch_means(t, x, from, to, blocks), from, to, blocks, z);
}

bool StationarityVerdict::stationary() const {
  for (const auto& s : signals)
    if (!s.ok) return false;
  return !signals.empty();
}

std::string StationarityVerdict::failed() const {
  std::string out;
  for (const auto& s : signals)
    if (!s.ok) out += (out.empty() ? "" : ", ") + s.name;
  return out;
}

}  // namespace sheardiff
