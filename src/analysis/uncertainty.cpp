#include "sheardiff/analysis/uncertainty.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sheardiff {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Sums of samples by block of [t_from, t_to], and the batch means they give. A bin of samples
// enters whole, at its time, with its sum and count; a lone sample is a bin of one.
class BlockSums {
 public:
  BlockSums(double t_from, double t_to, long blocks) : from_(t_from), to_(t_to), blocks_(blocks) {
    if (blocks < 1 || !(t_to > t_from))
      throw std::invalid_argument(
          fmt::format("batch_means: need blocks >= 1 and t_to > t_from (got {}, [{}, {}])", blocks,
                      t_from, t_to));
    width_ = (t_to - t_from) / static_cast<double>(blocks);
    sum_.assign(static_cast<std::size_t>(blocks), 0.0);
    count_.assign(static_cast<std::size_t>(blocks), 0.0);
  }
  void add(double t, double sum, double count) {
    if (t < from_ || t > to_) return;
    const auto b =
        static_cast<std::size_t>(std::min(blocks_ - 1, static_cast<long>((t - from_) / width_)));
    sum_[b] += sum;
    count_[b] += count;
    total_ += sum;
    n_ += count;
  }
  BatchMeans result() const {
    BatchMeans out;
    out.mean = n_ > 0 ? total_ / n_ : kNaN;
    for (std::size_t b = 0; b < sum_.size(); ++b)
      if (count_[b] > 0) out.block_means.push_back(sum_[b] / count_[b]);
    out.blocks = static_cast<long>(out.block_means.size());
    if (out.blocks < 2) {
      out.err = kNaN;
      return out;
    }
    double m = 0;
    for (double v : out.block_means) m += v;
    m /= static_cast<double>(out.blocks);
    double s = 0;
    for (double v : out.block_means) s += (v - m) * (v - m);
    out.err = std::sqrt(s / static_cast<double>(out.blocks - 1) / static_cast<double>(out.blocks));
    return out;
  }

 private:
  double from_, to_, width_ = 0;
  long blocks_;
  std::vector<double> sum_, count_;
  double total_ = 0, n_ = 0;
};

}  // namespace

BinnedSeries::BinnedSeries(std::size_t signals, std::size_t max_bins)
    : signals_(signals), max_bins_(max_bins) {
  if (max_bins < 2 || max_bins % 2 != 0)
    throw std::invalid_argument(
        fmt::format("BinnedSeries: max_bins {} is not even and >= 2", max_bins));
}

void BinnedSeries::add(double t, const std::vector<double>& x) {
  if (x.size() != signals_)
    throw std::invalid_argument(
        fmt::format("BinnedSeries: {} values for {} signals", x.size(), signals_));
  if (n_.empty() || n_.back() >= static_cast<double>(per_bin_)) {
    if (n_.size() == max_bins_) {
      // Full: join neighbours, so that the bins (each now twice as long) fill again by halves.
      const std::size_t half = max_bins_ / 2;
      for (std::size_t k = 0; k < half; ++k) {
        n_[k] = n_[2 * k] + n_[2 * k + 1];
        t_sum_[k] = t_sum_[2 * k] + t_sum_[2 * k + 1];
        for (std::size_t s = 0; s < signals_; ++s) {
          sum_[k * signals_ + s] = sum_[2 * k * signals_ + s] + sum_[(2 * k + 1) * signals_ + s];
          count_[k * signals_ + s] =
              count_[2 * k * signals_ + s] + count_[(2 * k + 1) * signals_ + s];
        }
      }
      n_.resize(half), t_sum_.resize(half);
      sum_.resize(half * signals_), count_.resize(half * signals_);
      per_bin_ *= 2;
    }
    n_.push_back(0.0), t_sum_.push_back(0.0);
    sum_.resize(sum_.size() + signals_, 0.0), count_.resize(count_.size() + signals_, 0.0);
  }
  const std::size_t k = n_.size() - 1;
  n_[k] += 1.0;
  t_sum_[k] += t;
  for (std::size_t s = 0; s < signals_; ++s)
    if (std::isfinite(x[s])) sum_[k * signals_ + s] += x[s], count_[k * signals_ + s] += 1.0;
  ++samples_;
  last_t_ = t;
}

void BinnedSeries::serialize(Archive& a) {
  std::uint64_t signals = signals_, max_bins = max_bins_;
  a.io(signals), a.io(max_bins);
  signals_ = signals, max_bins_ = max_bins;
  a.io(per_bin_), a.io(samples_), a.io(last_t_);
  a.io(n_), a.io(t_sum_), a.io(sum_), a.io(count_);
  if (a.loading() && (t_sum_.size() != n_.size() || sum_.size() != n_.size() * signals_ ||
                      count_.size() != sum_.size() || n_.size() > max_bins_))
    throw std::runtime_error("checkpoint: a binned series whose sizes do not match");
}

BatchMeans batch_means(const BinnedSeries& x, std::size_t s, double t_from, double t_to,
                       long blocks) {
  BlockSums b(t_from, t_to, blocks);
  for (std::size_t k = 0; k < x.bins(); ++k)
    if (x.count(k, s) > 0.0) b.add(x.time(k), x.sum(k, s), x.count(k, s));
  return b.result();
}

double jackknife_err(const std::vector<double>& x) {
  const auto n = static_cast<double>(x.size());
  if (x.size() < 2) return kNaN;
  double mean = 0;
  for (double v : x) {
    if (!std::isfinite(v)) return kNaN;
    mean += v / n;
  }
  double s = 0;
  for (double v : x) s += (v - mean) * (v - mean);
  return std::sqrt((n - 1.0) / n * s);
}

BatchMeans batch_means(const std::vector<double>& t, const std::vector<double>& x, double t_from,
                       double t_to, long blocks) {
  if (t.size() != x.size())
    throw std::invalid_argument(
        fmt::format("batch_means: {} times but {} samples", t.size(), x.size()));
  BlockSums b(t_from, t_to, blocks);
  for (std::size_t k = 0; k < t.size(); ++k)
    if (std::isfinite(x[k])) b.add(t[k], x[k], 1.0);
  return b.result();
}

namespace {

// The estimator's variance from G (at least n x n, the increments' products summed over
// particles; only |k - l| below the window's longest lag and block_frames is read).
MsdSlopeError slope_error_from_gram(const Eigen::MatrixXd& gram, long increments, double particles,
                                    double dt, double lo, double hi, long block_frames) {
  MsdSlopeError out;
  out.block_frames = block_frames;
  out.blocks = increments / block_frames;
  if (out.blocks < 2)
    throw std::invalid_argument(fmt::format(
        "msd_slope_error: {} increments make fewer than 2 blocks of {}", increments, block_frames));
  // Whole blocks only: the estimate is that of the first blocks * block_frames increments.
  const long n = out.blocks * block_frames;
  const long frames = n + 1;
  out.increments_used = n;

  // OLS slope weights of MSD(L) over the window's lags: slope = sum_L c_L MSD(L), D = slope/2.
  std::vector<long> lags;
  const double tol = 1e-9;
  for (long L = std::max(1L, static_cast<long>(std::ceil(lo / dt - tol)));
       L <= std::min(frames - 1, static_cast<long>(std::floor(hi / dt + tol))); ++L)
    lags.push_back(L);
  if (lags.size() < 3)
    throw std::invalid_argument(
        fmt::format("msd_slope_error: the window [{}, {}] holds {} lags of {} frames, need 3", lo,
                    hi, lags.size(), frames));
  double tbar = 0;
  for (long L : lags) tbar += static_cast<double>(L) * dt / static_cast<double>(lags.size());
  double sxx = 0;
  for (long L : lags) sxx += std::pow(static_cast<double>(L) * dt - tbar, 2);
  std::vector<double> weight(lags.size());
  for (std::size_t i = 0; i < lags.size(); ++i)
    weight[i] = (static_cast<double>(lags[i]) * dt - tbar) / (2.0 * sxx) /
                (particles * static_cast<double>(frames - lags[i]));

  // W(k, k + s): how much the product of increments k and k + s weighs in D. MSD(L) counts it
  // once per reference time t0 whose window [t0, t0 + L) holds both.
  const auto w_of = [&](long k, long s) {
    double w = 0;
    for (std::size_t i = 0; i < lags.size(); ++i) {
      const long L = lags[i];
      if (s >= L) continue;
      const long first = std::max(0L, k + s - L + 1), last = std::min(k, frames - 1 - L);
      if (last >= first) w += weight[i] * static_cast<double>(last - first + 1);
    }
    return w;
  };
  const auto g = gram.topLeftCorner(n, n);
  Eigen::MatrixXd w(n, n);
  for (long k = 0; k < n; ++k)
    for (long s = 0; k + s < n; ++s) w(k, k + s) = w(k + s, k) = w_of(k, s);

  const long nb = out.blocks, b = block_frames;
  // Q(B, B') = sum over k in B, l in B' of W G; D = sum over all block pairs.
  Eigen::MatrixXd q(nb, nb);
  for (long B = 0; B < nb; ++B)
    for (long C = 0; C < nb; ++C)
      q(B, C) = (w.block(B * b, C * b, b, b).array() * g.block(B * b, C * b, b, b).array()).sum();
  out.d = q.sum();
  for (long B = 0; B < nb; ++B)
    for (long C = B + 1; C < nb; ++C) out.var_between += std::pow(2.0 * q(B, C), 2);

  // Inside a block: Q_BB ~ sum_s wbar_B(s) h_B(s), h_B(s) = sum of G(k, k + s) over the block.
  Eigen::MatrixXd h(nb, b), wb(nb, b);
  for (long B = 0; B < nb; ++B)
    for (long s = 0; s < b; ++s) {
      double hs = 0, ws = 0;
      for (long k = B * b; k + s < (B + 1) * b; ++k) hs += g(k, k + s), ws += w(k, k + s);
      h(B, s) = hs;
      wb(B, s) = (s == 0 ? 1.0 : 2.0) * ws / static_cast<double>(b - s);
    }
  const Eigen::RowVectorXd hbar = h.colwise().mean();
  for (long B = 0; B < nb; ++B)
    for (long C = 0; C < nb; ++C)
      out.var_within += std::pow(wb.row(B).dot(h.row(C) - hbar), 2) / static_cast<double>(nb - 1);
  out.err = std::sqrt(out.var_between + out.var_within);
  return out;
}

}  // namespace

MsdSlopeError msd_slope_error(const Eigen::MatrixXd& y, double dt, double lo, double hi,
                              long block_frames) {
  if (!(dt > 0.0) || block_frames < 2 || y.cols() < 1)
    throw std::invalid_argument(fmt::format(
        "msd_slope_error: need dt > 0, block_frames >= 2 and particles (got {}, {}, {})", dt,
        block_frames, y.cols()));
  const long increments = static_cast<long>(y.rows()) - 1;
  const long n = std::max(0L, increments / block_frames * block_frames);
  const Eigen::MatrixXd inc = y.middleRows(1, n) - y.topRows(n);
  return slope_error_from_gram(inc * inc.transpose(), increments, static_cast<double>(y.cols()), dt,
                               lo, hi, block_frames);
}

IncrementGram::IncrementGram(long width, long band) : width_(width), band_(band) {
  if (width < 1 || band < 1)
    throw std::invalid_argument(
        fmt::format("IncrementGram: width {} and band {} must be >= 1", width, band));
  history_.assign(static_cast<std::size_t>((band + 1) * width), 0.0);
  msd_sum_.assign(static_cast<std::size_t>(band + 1), 0.0);
}

void IncrementGram::add(const double* y) {
  const auto w = static_cast<std::size_t>(width_);
  const long slots = band_ + 1;
  const auto at = [&](long t) { return history_.data() + (t % slots) * width_; };
  const long n = samples_;
  std::copy(y, y + w, at(n));
  // MSD sums: every origin n - k with a partner at n.
  for (long k = 1; k <= std::min(n, band_); ++k) {
    const double* o = at(n - k);
    double s = 0;
    for (std::size_t i = 0; i < w; ++i) s += (y[i] - o[i]) * (y[i] - o[i]);
    msd_sum_[static_cast<std::size_t>(k)] += s;
  }
  // The new increment l = n - 1 against itself and the band - 1 before it.
  if (n >= 1) {
    const long l = n - 1;
    const double* a1 = at(l + 1);
    const double* a0 = at(l);
    for (long s = 0; s < band_; ++s) {
      const long k = l - s;
      double gkl = 0;
      if (k >= 0) {
        const double* b1 = at(k + 1);
        const double* b0 = at(k);
        for (std::size_t i = 0; i < w; ++i) gkl += (b1[i] - b0[i]) * (a1[i] - a0[i]);
      }
      g_.push_back(gkl);
    }
  }
  ++samples_;
}

Eigen::MatrixXd IncrementGram::gram(long increments) const {
  const long n = std::min(increments, std::max(0L, samples_ - 1));
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(n, n);
  for (long l = 0; l < n; ++l)
    for (long s = 0; s < band_ && s <= l; ++s)
      g(l - s, l) = g(l, l - s) = g_[static_cast<std::size_t>(l * band_ + s)];
  return g;
}

MsdResult IncrementGram::msd(double dt, long max_lag) const {
  if (max_lag > band_ || max_lag >= samples_)
    throw std::invalid_argument(
        fmt::format("IncrementGram::msd: lag {} beyond the band {} or the {} samples", max_lag,
                    band_, samples_));
  MsdResult out;
  for (long k = 0; k <= max_lag; ++k) {
    const long pairs = width_ * (samples_ - k);
    out.lag.push_back(static_cast<double>(k) * dt);
    out.samples.push_back(pairs);
    out.msd.push_back(k == 0 ? 0.0
                             : msd_sum_[static_cast<std::size_t>(k)] / static_cast<double>(pairs));
  }
  return out;
}

MsdSlopeError msd_slope_error(const IncrementGram& g, double dt, double lo, double hi,
                              long block_frames) {
  if (!(dt > 0.0) || block_frames < 2)
    throw std::invalid_argument(fmt::format(
        "msd_slope_error: need dt > 0 and block_frames >= 2 (got {}, {})", dt, block_frames));
  // The gram holds |k - l| < band only: the window's lags and the blocks must fit in it.
  if (static_cast<long>(std::floor(hi / dt + 1e-9)) > g.band() || block_frames > g.band())
    throw std::invalid_argument(fmt::format(
        "msd_slope_error: lags up to {} and blocks of {} need a band of that many increments; "
        "the gram keeps {}",
        hi, block_frames, g.band()));
  const long increments = std::max(0L, g.samples() - 1);
  return slope_error_from_gram(g.gram(increments / block_frames * block_frames), increments,
                               static_cast<double>(g.width()), dt, lo, hi, block_frames);
}

void IncrementGram::serialize(Archive& a) {
  a.tag("increment_gram");
  long width = width_, band = band_;
  a.io(width), a.io(band);
  if (width != width_ || band != band_)
    throw std::runtime_error(fmt::format(
        "checkpoint: an increment gram of width {} and band {} where the configuration makes "
        "{} and {}",
        width, band, width_, band_));
  a.io(samples_), a.io(history_), a.io(g_), a.io(msd_sum_);
}

PersistenceEstimate persistence_with_errors(const Eigen::MatrixXd& v, double dt, long max_lag,
                                            long block_frames, const Eigen::MatrixXd* mask) {
  const long frames = static_cast<long>(v.rows());
  if (frames < 2 || v.cols() < 1 || max_lag < 1 || max_lag >= frames || block_frames < 1 ||
      !(dt > 0.0))
    throw std::invalid_argument(fmt::format(
        "persistence_with_errors: {} frames x {} particles, max_lag {}, block {} frames", frames,
        v.cols(), max_lag, block_frames));
  if (mask && (mask->rows() != v.rows() || mask->cols() != v.cols()))
    throw std::invalid_argument("persistence_with_errors: mask shape differs from v");
  const long nb = std::max(1L, frames / block_frames);
  // Frames as contiguous columns: each (origin, lag) term is one dot product over particles.
  const Eigen::MatrixXd vt = v.transpose();
  Eigen::MatrixXd origin = vt;
  if (mask) origin.array() *= mask->transpose().array();
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(nb, max_lag + 1), cnt = s;
  for (long t0 = 0; t0 < frames; ++t0) {
    const long B = std::min(nb - 1, t0 / block_frames);
    const double weight = mask ? mask->row(t0).sum() : static_cast<double>(v.cols());
    if (weight <= 0.0) continue;
    const auto a = origin.col(t0);
    for (long k = 0; k <= max_lag && t0 + k < frames; ++k) {
      s(B, k) += a.dot(vt.col(t0 + k));
      cnt(B, k) += weight;
    }
  }
  std::vector<double> lag;
  for (long k = 0; k <= max_lag; ++k) lag.push_back(static_cast<double>(k) * dt);
  return persistence_from_block_sums(lag, s, cnt);
}

PersistenceEstimate persistence_from_block_sums(const std::vector<double>& lag,
                                                const Eigen::MatrixXd& block_sum,
                                                const Eigen::MatrixXd& block_count) {
  const Eigen::RowVectorXd s_all = block_sum.colwise().sum();
  const Eigen::RowVectorXd n_all = block_count.colwise().sum();
  const auto correlation = [&](const Eigen::RowVectorXd& num, const Eigen::RowVectorXd& den) {
    Autocorrelation c;
    c.lag = lag;
    for (Eigen::Index k = 0; k < num.size(); ++k) c.c.push_back(den(k) > 0 ? num(k) / den(k) : 0.0);
    return c;
  };
  PersistenceEstimate out;
  out.blocks = block_sum.rows();
  out.c = correlation(s_all, n_all);
  out.p = persistence_time(out.c);
  out.dv = std::sqrt(out.p.c0);
  out.dv_err = out.psi_err = out.psi_e_err = out.psi_zero_err = out.psi_full_err = kNaN;
  if (out.blocks < 2) return out;
  std::vector<double> dv, psi, psi_e, psi_zero, psi_full;
  for (Eigen::Index B = 0; B < out.blocks; ++B) {
    const Autocorrelation c = correlation(s_all - block_sum.row(B), n_all - block_count.row(B));
    if (!(c.c[0] > 0.0)) {
      for (auto* x : {&dv, &psi, &psi_e, &psi_zero, &psi_full}) x->push_back(kNaN);
      continue;
    }
    const Persistence p = persistence_time(c);
    dv.push_back(std::sqrt(p.c0));
    psi.push_back(p.psi), psi_e.push_back(p.psi_e), psi_zero.push_back(p.psi_zero);
    psi_full.push_back(p.psi_full);
  }
  out.dv_err = jackknife_err(dv);
  out.psi_err = jackknife_err(psi);
  out.psi_e_err = jackknife_err(psi_e);
  out.psi_zero_err = jackknife_err(psi_zero);
  out.psi_full_err = jackknife_err(psi_full);
  return out;
}

MsdResult masked_mean_square_displacement(const Eigen::MatrixXd& y, const Eigen::MatrixXd& mask,
                                          double dt, long max_lag,
                                          const std::vector<long>& reference_frames) {
  const long frames = static_cast<long>(y.rows());
  if (mask.rows() != y.rows() || mask.cols() != y.cols())
    throw std::invalid_argument("masked_mean_square_displacement: mask shape differs from y");
  if (max_lag < 1 || max_lag >= frames || reference_frames.empty())
    throw std::invalid_argument(
        fmt::format("masked_mean_square_displacement: max_lag {} of {} frames, {} reference frames",
                    max_lag, frames, reference_frames.size()));
  const Eigen::MatrixXd by_frame = y.transpose();
  const Eigen::MatrixXd m = mask.transpose();
  std::vector<double> acc(static_cast<std::size_t>(max_lag) + 1, 0.0);
  double weight = 0;
  for (long t0 : reference_frames) {
    if (t0 < 0 || t0 + max_lag >= frames)
      throw std::invalid_argument(fmt::format(
          "masked_mean_square_displacement: reference frame {} with max_lag {} leaves [0, {})", t0,
          max_lag, frames));
    const auto base = by_frame.col(t0);
    const auto w = m.col(t0);
    weight += w.sum();
    for (long k = 1; k <= max_lag; ++k)
      acc[static_cast<std::size_t>(k)] += w.dot((by_frame.col(t0 + k) - base).cwiseAbs2());
  }
  MsdResult out;
  for (long k = 0; k <= max_lag; ++k) {
    out.lag.push_back(static_cast<double>(k) * dt);
    out.msd.push_back(weight > 0 ? acc[static_cast<std::size_t>(k)] / weight : kNaN);
    out.samples.push_back(static_cast<long>(weight));
  }
  return out;
}

}  // namespace sheardiff
