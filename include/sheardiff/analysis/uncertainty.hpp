#pragma once
#include <Eigen/Core>
#include <limits>
#include <vector>

#include "sheardiff/analysis/time_series.hpp"
#include "sheardiff/core/archive.hpp"

namespace sheardiff {

// Statistical errors of one run's measured quantities from the run's own data (docs/model.md
// section 9, "Error bars"). All three estimators cut the measured window into consecutive time
// blocks longer than the correlation time of what they average, so that blocks are close to
// independent while particles inside a block may be correlated in any way (collective motion
// is what makes independent runs scatter more than a particle count suggests).

// Mean of samples x taken at times t (ascending) from t_from on, and its standard error from
// the scatter of the means of `blocks` equal blocks of time (batch means). err is NaN when
// fewer than 2 blocks hold samples.
struct BatchMeans {
  double mean = 0, err = 0;
  long blocks = 0;
  std::vector<double> block_means;
};
BatchMeans batch_means(const std::vector<double>& t, const std::vector<double>& x, double t_from,
                       double t_to, long blocks);

// Samples of several signals taken at common ascending times, kept in at most max_bins bins of
// consecutive samples so that what a run carries (and checkpoints) does not grow with it: one
// sample a bin while they fit, then, each time the bins are full, neighbouring bins joined
// pairwise (a bin then holds 2^k samples). A bin keeps its samples' summed time and, per
// signal, the sum and the number of its finite values.
class BinnedSeries {
 public:
  BinnedSeries() = default;
  // max_bins: even, >= 2.
  explicit BinnedSeries(std::size_t signals, std::size_t max_bins = 2048);
  // The next sample: its time (not before the last one's) and one value per signal.
  void add(double t, const std::vector<double>& x);
  std::size_t signals() const { return signals_; }
  std::size_t bins() const { return n_.size(); }
  long samples() const { return samples_; }
  long samples_per_bin() const { return per_bin_; }
  double last_time() const { return last_t_; }  // NaN before the first sample
  // Bin k's mean time, and signal s's sum and count of finite values in it.
  double time(std::size_t k) const { return t_sum_[k] / n_[k]; }
  double sum(std::size_t k, std::size_t s) const { return sum_[k * signals_ + s]; }
  double count(std::size_t k, std::size_t s) const { return count_[k * signals_ + s]; }
  void serialize(Archive& a);

 private:
  std::size_t signals_ = 0, max_bins_ = 2;
  long per_bin_ = 1, samples_ = 0;
  double last_t_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> n_, t_sum_;    // per bin
  std::vector<double> sum_, count_;  // bins x signals
};

// batch_means of signal s of binned samples: each bin enters the block of its mean time. While
// every bin holds one sample this is batch_means of the samples, to the bit; once bins are
// joined, a bin that straddles a block boundary lies wholly in one block (a shift of at most
// half a bin, against blocks of many bins).
BatchMeans batch_means(const BinnedSeries& x, std::size_t s, double t_from, double t_to,
                       long blocks);

// The MSD-slope diffusion coefficient D of frames y (frames x particles, spacing dt), fitted
// over lags [lo, hi] by OLS of MSD against lag using every frame as a reference time, and its
// variance. The estimator is a quadratic form in the frame-to-frame increments,
// D = sum_kl W_kl G_kl with G = (increments) (increments)^T summed over particles, so its
// variance splits exactly into terms between different time blocks and terms inside one
// block. Between blocks: the Rademacher wild-bootstrap variance sum_{B<B'} (2 Q_BB')^2, exact
// in expectation when increments of different blocks are uncorrelated. Inside a block: from the
// covariance, over blocks, of the block's increment products at each separation (stationary
// statistics). Tested for coverage on random walks, Ornstein-Uhlenbeck walks and walks with a
// common collective mode (tests/unit/test_uncertainty.cpp).
struct MsdSlopeError {
  double d = 0;    // the all-reference-times estimate on these frames
  double err = 0;  // sqrt(var_between + var_within)
  double var_between = 0, var_within = 0;
  long blocks = 0, block_frames = 0, increments_used = 0;
};
MsdSlopeError msd_slope_error(const Eigen::MatrixXd& y, double dt, double lo, double hi,
                              long block_frames);

// What msd_slope_error needs of a series, accumulated sample by sample without keeping it: the
// products of its increments summed over particles, G(k, l) = sum_i (y_i(k+1) - y_i(k))
// (y_i(l+1) - y_i(l)) for |k - l| < band, and the every-origin MSD sums up to lag band. Memory:
// band + 1 samples, and band numbers per sample (independent of the particle count).
class IncrementGram {
 public:
  IncrementGram() = default;
  IncrementGram(long width, long band);
  void add(const double* y);
  long samples() const { return samples_; }
  long width() const { return width_; }
  long band() const { return band_; }
  // G over the first `increments` increments, zero where |k - l| >= band.
  Eigen::MatrixXd gram(long increments) const;
  // The MSD at lags 0 .. max_lag (<= band) over every origin, as mean_square_displacement.
  MsdResult msd(double dt, long max_lag) const;
  void serialize(Archive& a);

 private:
  long width_ = 0, band_ = 0, samples_ = 0;
  std::vector<double> history_;  // the last band + 1 samples
  std::vector<double> g_;        // per increment l: G(l - s, l), s = 0 .. band - 1
  std::vector<double> msd_sum_;  // per lag 0 .. band
};

// msd_slope_error of the series the gram accumulated (equal to round-off); the window's
// longest lag and block_frames must lie within its band.
MsdSlopeError msd_slope_error(const IncrementGram& g, double dt, double lo, double hi,
                              long block_frames);

// The velocity autocorrelation of v (frames x particles) summed separately for each block of
// reference times (origins in the block, partners up to max_lag later, possibly in the next
// block), optionally weighted by mask (same shape, 0/1: whether particle i at origin t counts,
// e.g. "in the bulk"). The sums over all blocks give the usual C(tau); leaving one block out
// gives the delete-one-block jackknife. Psi (every definition) and dv with their errors come
// from that jackknife.
struct PersistenceEstimate {
  Autocorrelation c;  // C(tau) over all origins (mask-weighted)
  double dv = 0, dv_err = 0;
  Persistence p;  // from c
  double psi_err = 0, psi_e_err = 0, psi_zero_err = 0, psi_full_err = 0;
  long blocks = 0;
};
PersistenceEstimate persistence_with_errors(const Eigen::MatrixXd& v, double dt, long max_lag,
                                            long block_frames,
                                            const Eigen::MatrixXd* mask = nullptr);
// The same from sums already split by block: block_sum(B, k) and block_count(B, k) are block B's
// sum of v(t) v(t + lag[k]) and its weight. Both the frame analysis and the streaming
// correlator end here, so their dv, Psi and errors agree by construction.
PersistenceEstimate persistence_from_block_sums(const std::vector<double>& lag,
                                                const Eigen::MatrixXd& block_sum,
                                                const Eigen::MatrixXd& block_count);
// Delete-one jackknife standard error of leave-one-out values x (NaN if fewer than two or any
// is not finite).
double jackknife_err(const std::vector<double>& x);

// MSD over the given reference frames counting particle i at origin t0 only where
// mask(t0, i) != 0 (the bulk-only MSD); the unmasked overload is in time_series.hpp.
MsdResult masked_mean_square_displacement(const Eigen::MatrixXd& y, const Eigen::MatrixXd& mask,
                                          double dt, long max_lag,
                                          const std::vector<long>& reference_frames);

}  // namespace sheardiff
