#include "sheardiff/analysis/correlator.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <stdexcept>

namespace sheardiff {

MultipleTauCorrelator::MultipleTauCorrelator(Kind kind, long width, long max_lag, long block,
                                             bool masked, int points)
    : kind_(kind),
      width_(width),
      max_lag_(max_lag),
      block_(block),
      points_(points),
      masked_(masked) {
  if (width < 1 || max_lag < 1 || block < 1 || points < 4 || points % 2 != 0)
    throw std::invalid_argument(fmt::format(
        "MultipleTauCorrelator: width {}, max_lag {}, block {}, points {} (need >= 1, >= 1, "
        ">= 1 and an even number >= 4)",
        width, max_lag, block, points));
  const long half = points / 2;
  levels_ = 1;
  while (static_cast<long>(points - 1) << (levels_ - 1) < max_lag) ++levels_;
  for (int l = 0; l < levels_; ++l) {
    level_first_.push_back(static_cast<long>(lags_.size()));
    for (long k = l == 0 ? 0 : half; k < points; ++k) {
      const long lag = k << l;
      if (lag <= max_lag) lags_.push_back(lag);
    }
  }
  history_.resize(static_cast<std::size_t>(levels_));
  for (int l = 0; l < levels_; ++l)
    history_[static_cast<std::size_t>(l)].assign(
        static_cast<std::size_t>((l == 0 ? points : half) * width), 0.0);
  if (masked_) {
    history_mask_.resize(static_cast<std::size_t>(levels_));
    for (int l = 0; l < levels_; ++l)
      history_mask_[static_cast<std::size_t>(l)].assign(
          static_cast<std::size_t>((l == 0 ? points : half) * width), 0);
  }
}

std::size_t MultipleTauCorrelator::lag_index(int level, long k) const {
  return static_cast<std::size_t>(level_first_[static_cast<std::size_t>(level)] +
                                  (level == 0 ? k : k - points_ / 2));
}

double* MultipleTauCorrelator::slot(int level, long index) {
  const long n = level == 0 ? points_ : points_ / 2;
  return history_[static_cast<std::size_t>(level)].data() + (index % n) * width_;
}

std::uint8_t* MultipleTauCorrelator::mask_slot(int level, long index) {
  const long n = level == 0 ? points_ : points_ / 2;
  return history_mask_[static_cast<std::size_t>(level)].data() + (index % n) * width_;
}

void MultipleTauCorrelator::correlate(int level, long lag_samples, const double* origin,
                                      const std::uint8_t* origin_mask, const double* x) {
  const long t0 = samples_ - lag_samples;
  const auto j = lag_index(level, lag_samples >> level);
  const std::size_t nlags = lags_.size();
  const auto b = static_cast<std::size_t>(t0 / block_);
  if (sum_.size() < (b + 1) * nlags) {
    for (auto* v : {&sum_, &count_}) v->resize((b + 1) * nlags, 0.0);
    if (masked_)
      for (auto* v : {&sum_masked_, &count_masked_}) v->resize((b + 1) * nlags, 0.0);
  }
  double s = 0.0, sm = 0.0, cm = 0.0;
  if (kind_ == Kind::product) {
    for (long i = 0; i < width_; ++i) {
      const double f = origin[i] * x[i];
      s += f;
      if (origin_mask && origin_mask[i]) sm += f, cm += 1.0;
    }
  } else {
    for (long i = 0; i < width_; ++i) {
      const double dx = x[i] - origin[i];
      const double f = dx * dx;
      s += f;
      if (origin_mask && origin_mask[i]) sm += f, cm += 1.0;
    }
  }
  sum_[b * nlags + j] += s;
  count_[b * nlags + j] += static_cast<double>(width_);
  if (masked_) {
    sum_masked_[b * nlags + j] += sm;
    count_masked_[b * nlags + j] += cm;
  }
}

void MultipleTauCorrelator::add(const double* x, const std::uint8_t* mask) {
  if (masked_ != (mask != nullptr))
    throw std::invalid_argument(masked_ ? "MultipleTauCorrelator: a masked correlator needs masks"
                                        : "MultipleTauCorrelator: a mask given to an unmasked one");
  const long n = samples_;
  const long half = points_ / 2;
  const auto w = static_cast<std::size_t>(width_);
  // What leaves a level passes to the next (if the sample is on that level's grid).
  std::vector<double> leaving, entering;
  std::vector<std::uint8_t> leaving_mask, entering_mask;

  // Level 0: every sample, lags 0 .. points-1.
  double* s0 = slot(0, n);
  if (n >= points_) {
    leaving.assign(s0, s0 + w);
    if (masked_) leaving_mask.assign(mask_slot(0, n), mask_slot(0, n) + w);
  }
  std::copy(x, x + w, s0);
  if (masked_) std::copy(mask, mask + w, mask_slot(0, n));
  for (long k = 0; k < points_ && k <= n && k <= max_lag_; ++k)
    correlate(0, k, slot(0, n - k), masked_ ? mask_slot(0, n - k) : nullptr, x);

  // Level l: on samples n that are multiples of 2^l, lags k 2^l with k = points/2 .. points-1.
  for (int l = 1; l < levels_ && n % (1L << l) == 0; ++l) {
    const long m = n >> l;  // this sample's index on the level's grid
    if (m < half) break;    // nothing old enough yet to enter the level (or any above it)
    std::swap(entering, leaving);
    std::swap(entering_mask, leaving_mask);
    leaving.clear();
    leaving_mask.clear();
    // The entrant (index m - half on the grid) takes the slot of the one aged `points`.
    double* e = slot(l, m - half);
    if (m >= points_) {
      leaving.assign(e, e + w);
      if (masked_) leaving_mask.assign(mask_slot(l, m - half), mask_slot(l, m - half) + w);
    }
    std::copy(entering.begin(), entering.end(), e);
    if (masked_) std::copy(entering_mask.begin(), entering_mask.end(), mask_slot(l, m - half));
    for (long k = half; k < points_ && k <= m && (k << l) <= max_lag_; ++k)
      correlate(l, k << l, slot(l, m - k), masked_ ? mask_slot(l, m - k) : nullptr, x);
  }
  ++samples_;
}

const double* MultipleTauCorrelator::past(long age) const {
  const long n = samples_ - 1, t = n - age;
  if (age < 0 || t < 0) return nullptr;
  const long half = points_ / 2;
  if (age < points_) return history_[0].data() + (t % points_) * width_;
  for (int l = 1; l < levels_; ++l) {
    const long step = 1L << l;
    if (age % step != 0 || n % step != 0) return nullptr;
    const long k = age >> l;
    if (k >= half && k < points_)
      return history_[static_cast<std::size_t>(l)].data() + ((t >> l) % half) * width_;
  }
  return nullptr;
}

void MultipleTauCorrelator::coarsen_blocks(long factor) {
  if (factor < 1) throw std::invalid_argument("MultipleTauCorrelator: coarsen by less than 1");
  const std::size_t nlags = lags_.size();
  for (auto* v : {&sum_, &count_, &sum_masked_, &count_masked_}) {
    const std::size_t blocks = v->size() / nlags;
    std::vector<double> out(
        ((blocks + static_cast<std::size_t>(factor) - 1) / static_cast<std::size_t>(factor)) *
            nlags,
        0.0);
    for (std::size_t b = 0; b < blocks; ++b)
      for (std::size_t j = 0; j < nlags; ++j)
        out[b / static_cast<std::size_t>(factor) * nlags + j] += (*v)[b * nlags + j];
    *v = std::move(out);
  }
  block_ *= factor;
}

double MultipleTauCorrelator::sum(long b, std::size_t j, bool masked) const {
  return (masked ? sum_masked_ : sum_)[static_cast<std::size_t>(b) * lags_.size() + j];
}

double MultipleTauCorrelator::count(long b, std::size_t j, bool masked) const {
  return (masked ? count_masked_ : count_)[static_cast<std::size_t>(b) * lags_.size() + j];
}

void MultipleTauCorrelator::serialize(Archive& a) {
  a.tag("correlator");
  // The shape comes from the configuration; a stored one that differs is a foreign file.
  std::uint8_t kind = static_cast<std::uint8_t>(kind_);
  long width = width_, max_lag = max_lag_, block = block_;
  int points = points_;
  std::uint8_t masked = masked_ ? 1 : 0;
  a.io(kind), a.io(width), a.io(max_lag), a.io(block), a.io(points), a.io(masked);
  // Blocks may have been joined since (coarsen_blocks): a whole multiple of the configured.
  if (kind != static_cast<std::uint8_t>(kind_) || width != width_ || max_lag != max_lag_ ||
      block < 1 || block % block_ != 0 || points != points_ || (masked != 0) != masked_)
    throw std::runtime_error(fmt::format(
        "checkpoint: a correlator of width {}, max lag {}, block {} where the configuration "
        "makes one of width {}, max lag {}, block {}",
        width, max_lag, block, width_, max_lag_, block_));
  block_ = block;
  a.io(samples_);
  a.io(history_);
  a.io(history_mask_);
  a.io(sum_), a.io(count_), a.io(sum_masked_), a.io(count_masked_);
}

}  // namespace sheardiff
