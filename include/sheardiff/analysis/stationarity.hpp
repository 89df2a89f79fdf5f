#pragma once
#include <string>
#include <vector>

#include "sheardiff/analysis/uncertainty.hpp"

namespace sheardiff {

// Whether a measured window was stationary, judged by physical signals against their own noise
// (docs/model.md, "Steady state"). A detector that compares the halves of a short window with a
// fixed tolerance passes a slow drift; these tests grow stricter as the window grows, because
// the error of a window's mean shrinks while a drift's effect on it does not.
//
// Each signal is a time series sampled at times t. Its errors come from batch means over
// `blocks` equal time blocks of [from, to] (blocks longer than the signal's correlation time
// are close to independent), never from the sample count.
struct DriftSignal {
  std::string name;
  double value = 0;  // the window's mean minus `expected`, or the trend's change
  double expected = 0;
  double err = 0;    // standard error of value from the block scatter (NaN: too few blocks)
  double limit = 0;  // |value| allowed
  bool ok = false;   // |value| <= limit (false when err is not finite)
};

// The window mean of x is `expected` within z standard errors: limit = z * err.
DriftSignal mean_within_noise(const std::string& name, const std::vector<double>& t,
                              const std::vector<double>& x, double expected, double from, double to,
                              long blocks, double z);

// The window mean of x is `expected` within a fixed tolerance: limit = tolerance (err is
// reported, not used).
DriftSignal mean_within_tolerance(const std::string& name, const std::vector<double>& t,
                                  const std::vector<double>& x, double expected, double from,
                                  double to, long blocks, double tolerance);

// The change of x across the window, slope * (to - from) of the OLS line through the block
// means, is zero within z standard errors of that change (from the residual scatter of the
// block means about the line, blocks - 2 degrees of freedom; needs >= 4 blocks).
DriftSignal trend_within_noise(const std::string& name, const std::vector<double>& t,
                               const std::vector<double>& x, double from, double to, long blocks,
                               double z);

// The same three tests on batch means already formed (of samples or of binned samples,
// BinnedSeries); `from`, `to` and `blocks` are those the means were formed over.
DriftSignal mean_within_noise(const std::string& name, const BatchMeans& b, double expected,
                              double z);
DriftSignal mean_within_tolerance(const std::string& name, const BatchMeans& b, double expected,
                                  double tolerance);
DriftSignal trend_within_noise(const std::string& name, const BatchMeans& b, double from, double to,
                               long blocks, double z);

struct StationarityVerdict {
  std::vector<DriftSignal> signals;
  bool stationary() const;
  // Names of the failed signals, comma separated ("" when stationary).
  std::string failed() const;
};

}  // namespace sheardiff
