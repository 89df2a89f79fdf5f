#pragma once
#include <cstdint>
#include <vector>

#include "sheardiff/core/archive.hpp"

namespace sheardiff {

// A time correlation of a signal with one value per particle, accumulated sample by sample
// while a run goes (docs/model.md section 9): the velocity autocorrelation <a(t0) a(t0 + tau)>
// (Kind::product) or the mean square displacement <(a(t0 + tau) - a(t0))^2>
// (Kind::squared_difference), summed over particles and over every origin t0 that has a
// partner, so memory does not grow with the run.
//
// Multiple-tau with subsampling, not averaging: level 0 correlates every sample at lags
// 0 .. points-1; level l >= 1 correlates every 2^l-th sample at lags k 2^l, k = points/2 ..
// points-1. A level keeps the instantaneous values (block averages would turn a velocity into a
// displacement over the block, another velocity definition), so on the same samples level l
// equals the all-origin frame analysis of the samples subsampled by 2^l (tested). Memory:
// points + (points/2) (levels - 1) samples of the signal, levels = what max_lag needs.
//
// Sums are kept per block of origins (`block` samples each), for block errors, and a second set
// counts only origins whose mask byte is set (the bulk of the pressure cell).
class MultipleTauCorrelator {
 public:
  enum class Kind : std::uint8_t { product = 0, squared_difference = 1 };
  MultipleTauCorrelator() = default;
  // width: values per sample (particles); max_lag: longest lag, in samples; block: origins per
  // block; masked: every sample comes with width mask bytes; points: even, >= 4.
  MultipleTauCorrelator(Kind kind, long width, long max_lag, long block, bool masked,
                        int points = 16);

  // The next sample: width values, and width mask bytes if the correlator is masked.
  void add(const double* x, const std::uint8_t* mask = nullptr);

  long samples() const { return samples_; }
  long width() const { return width_; }
  long block() const { return block_; }
  bool masked() const { return masked_; }
  // Every lag the correlator measures (in samples, ascending, up to max_lag), each once.
  const std::vector<long>& lags() const { return lags_; }
  // Blocks of origins seen so far (the last one may be partial).
  long blocks() const { return static_cast<long>(sum_.size() / lags_.size()); }
  // Per block b and lag index j: the summed correlation and the number of (particle, origin)
  // pairs; masked = only origins whose mask byte was set.
  double sum(long b, std::size_t j, bool masked = false) const;
  double count(long b, std::size_t j, bool masked = false) const;
  // Joins every `factor` consecutive blocks into one (block *= factor): once the final blocks
  // are known, the finer ones need not be kept.
  void coarsen_blocks(long factor);

  // The stored sample `age` samples before the latest one, if the grid keeps it (ages 0 ..
  // points-1, and k 2^l for k = points/2 .. points-1 when the latest index is a multiple of
  // 2^l); else nullptr.
  const double* past(long age) const;

  void serialize(Archive& a);

 private:
  void correlate(int level, long lag, const double* origin, const std::uint8_t* origin_mask,
                 const double* x);
  std::size_t lag_index(int level, long k) const;
  double* slot(int level, long index);
  std::uint8_t* mask_slot(int level, long index);

  Kind kind_ = Kind::product;
  long width_ = 0, max_lag_ = 0, block_ = 1;
  int points_ = 16, levels_ = 0;
  bool masked_ = false;
  long samples_ = 0;
  std::vector<long> lags_;
  std::vector<long> level_first_;  // index into lags_ of each level's first lag
  // Level 0: the last `points` samples (ages 0 .. points-1); level l >= 1: the every-2^l-th
  // samples aged points/2 .. points-1 in units of 2^l, each passed on from level l-1 as it
  // leaves that level.
  std::vector<std::vector<double>> history_;
  std::vector<std::vector<std::uint8_t>> history_mask_;
  std::vector<double> sum_, count_, sum_masked_, count_masked_;  // blocks x lags
};

}  // namespace sheardiff
