#include "sheardiff/analysis/diffusion.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sheardiff/io/summary_keys.hpp"

namespace sheardiff {

namespace {

nlohmann::json number_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

}  // namespace

Eigen::MatrixXd bulk_mask(const Eigen::MatrixXd& y, const Eigen::VectorXd& bottom,
                          const Eigen::VectorXd& top, double exclusion) {
  if (bottom.size() != y.rows() || top.size() != y.rows())
    throw std::invalid_argument(fmt::format("bulk_mask: {} frames but {} / {} wall heights",
                                            y.rows(), bottom.size(), top.size()));
  Eigen::MatrixXd m(y.rows(), y.cols());
  for (Eigen::Index t = 0; t < y.rows(); ++t)
    for (Eigen::Index i = 0; i < y.cols(); ++i)
      m(t, i) = y(t, i) >= bottom(t) + exclusion && y(t, i) <= top(t) - exclusion ? 1.0 : 0.0;
  return m;
}

namespace {

// Origins are summed per 1/kParts of an error block until the window's length decides the blocks.
constexpr long kParts = 16;

// What the correlator's sums give once its parts of blocks of origins are joined into `nb`
// error blocks of `per_block` parts (the last one takes the remainder): the correlation over
// every origin and one with each block left out.
struct JoinedSums {
  std::vector<long> lag;                   // samples, lags that have pairs
  std::vector<std::size_t> index;          // their index in the correlator
  Eigen::RowVectorXd sum, count;           // over every origin
  Eigen::MatrixXd block_sum, block_count;  // nb x lags
};

JoinedSums join_blocks(const MultipleTauCorrelator& c, long per_block, long nb, bool masked) {
  JoinedSums j;
  const auto& lags = c.lags();
  for (std::size_t k = 0; k < lags.size(); ++k) {
    double n = 0;
    for (long b = 0; b < c.blocks(); ++b) n += c.count(b, k, false);
    if (n > 0) j.lag.push_back(lags[k]), j.index.push_back(k);
  }
  const auto nl = static_cast<Eigen::Index>(j.lag.size());
  j.block_sum = Eigen::MatrixXd::Zero(nb, nl);
  j.block_count = Eigen::MatrixXd::Zero(nb, nl);
  for (long b = 0; b < c.blocks(); ++b) {
    const long B = std::min(nb - 1, b / per_block);
    for (Eigen::Index k = 0; k < nl; ++k) {
      j.block_sum(B, k) += c.sum(b, j.index[static_cast<std::size_t>(k)], masked);
      j.block_count(B, k) += c.count(b, j.index[static_cast<std::size_t>(k)], masked);
    }
  }
  j.sum = j.block_sum.colwise().sum();
  j.count = j.block_count.colwise().sum();
  return j;
}

std::vector<double> lag_strains(const std::vector<long>& lag, double dt) {
  std::vector<double> t;
  for (long k : lag) t.push_back(static_cast<double>(k) * dt);
  return t;
}

PersistenceEstimate persistence_from(const JoinedSums& j, double dt) {
  return persistence_from_block_sums(lag_strains(j.lag, dt), j.block_sum, j.block_count);
}

MsdResult msd_from(const JoinedSums& j, double dt, double particles) {
  MsdResult m;
  m.lag = lag_strains(j.lag, dt);
  for (Eigen::Index k = 0; k < j.sum.size(); ++k) {
    m.msd.push_back(j.count(k) > 0 ? j.sum(k) / j.count(k) : std::nan(""));
    m.samples.push_back(std::lround(j.count(k) / particles));
  }
  return m;
}

// Error blocks over `samples` samples whose origins were summed per `mini` samples
// (analysis.error_block / kParts): kParts parts each, fewer when that leaves fewer than four
// blocks, so that a window down to a quarter of an error block still gets four.
struct ErrorBlocks {
  long block_samples = 1, blocks = 1;
};
ErrorBlocks error_blocks(long samples, long mini) {
  const long parts = samples / mini;
  const long per_block = parts >= 4 * kParts ? kParts : std::max(1L, parts / 4);
  ErrorBlocks b;
  b.block_samples = per_block * mini;
  b.blocks = std::max(1L, samples / b.block_samples);
  return b;
}

}  // namespace

DiffusionAccumulator::DiffusionAccumulator(const DiffusionSettings& s, double sample_strain,
                                           long particles, bool bulk, bool non_affine_x)
    : s_(s), dt_(sample_strain), particles_(particles), bulk_(bulk), x_(non_affine_x) {
  if (!(sample_strain > 0.0) || particles < 1 || !(s.coarse_strain > 0.0) ||
      !(s.error_block > 0.0) || !(s.window_hi > s.window_lo) || !(s.vacf_max_lag > 0.0))
    throw std::invalid_argument(fmt::format(
        "DiffusionAccumulator: sample spacing {} for {} particles, coarse spacing {}, error "
        "block {}, window [{}, {}], VACF lag {}",
        sample_strain, particles, s.coarse_strain, s.error_block, s.window_lo, s.window_hi,
        s.vacf_max_lag));
  // Origins are summed per part of an error block: a window too short for four whole
  // blocks still gets four shorter ones.
  mini_ = std::max(1L, std::lround(s.error_block / kParts / dt_));
  stride_ = std::max(1L, std::lround(s.coarse_strain / dt_));
  const double dtc = static_cast<double>(stride_) * dt_;
  const long vacf_lag = std::max(1L, static_cast<long>(std::ceil(s.vacf_max_lag / dt_ - 1e-9)));
  const long msd_lag = static_cast<long>(std::ceil(s.window_hi / dt_ - 1e-9)) + 1;
  const long band = std::max(static_cast<long>(std::ceil(s.window_hi / dtc - 1e-9)) + 1,
                             std::max(2L, std::lround(s.error_block / dtc)));
  using K = MultipleTauCorrelator::Kind;
  // Only the VACF's error comes from its blocks (D's from the gram): the MSDs keep one block.
  constexpr long kOneBlock = 1L << 62;
  vacf_ = MultipleTauCorrelator(K::product, particles, vacf_lag, mini_, bulk);
  msd_ = MultipleTauCorrelator(K::squared_difference, particles, msd_lag, kOneBlock, bulk);
  if (x_)
    msd_x_ = MultipleTauCorrelator(K::squared_difference, particles, msd_lag, kOneBlock, false);
  coarse_ = IncrementGram(particles, band);
  for (double delta : s.velocity_intervals) {
    // Delta as k 2^l samples with k <= 15 (k >= 8 above level 0): what the MSD's grid keeps.
    Interval iv;
    const double m = delta / dt_;
    while (m / static_cast<double>(1L << iv.level) >= 15.5) ++iv.level;
    iv.k = std::max(1L, std::lround(m / static_cast<double>(1L << iv.level)));
    if ((iv.k << iv.level) > msd_lag)
      throw std::invalid_argument(
          fmt::format("analysis.velocity_intervals: {:g} is longer than the MSD's lags (analysis."
                      "msd_window_hi = {:g})",
                      delta, s.window_hi));
    const double spacing = static_cast<double>(1L << iv.level) * dt_;
    iv.mini = std::max(1L, std::lround(s.error_block / kParts / spacing));
    const long lag = std::max(1L, static_cast<long>(std::ceil(s.vacf_max_lag / spacing - 1e-9)));
    iv.c = MultipleTauCorrelator(K::product, particles, lag, iv.mini, false);
    intervals_.push_back(std::move(iv));
  }
}

void DiffusionAccumulator::add(const double* y, const double* vy, const double* x,
                               const std::uint8_t* bulk) {
  if ((x != nullptr) != x_ || (bulk != nullptr) != bulk_)
    throw std::invalid_argument(
        "DiffusionAccumulator: a sample without the x or bulk data the "
        "accumulator was made for");
  if (samples() % stride_ == 0) coarse_.add(y);
  const long n = samples();
  vacf_.add(vy, bulk);
  msd_.add(y, bulk);
  if (x_) msd_x_.add(x);
  for (Interval& iv : intervals_) {
    const long step = 1L << iv.level, span = iv.k << iv.level;
    if (n % step != 0 || n < span) continue;
    const double* before = msd_.past(span);
    const double delta = static_cast<double>(span) * dt_;
    u_.resize(static_cast<std::size_t>(particles_));
    for (long i = 0; i < particles_; ++i)
      u_[static_cast<std::size_t>(i)] = (y[i] - before[i]) / delta;
    iv.c.add(u_.data());
    if (iv.c.samples() == 4 * kParts * iv.mini && iv.c.block() == iv.mini)
      iv.c.coarsen_blocks(kParts);
  }
  // From 4 kParts parts on, blocks are whole error blocks (report()): keep those only.
  if (samples() == 4 * kParts * mini_ && vacf_.block() == mini_) vacf_.coarsen_blocks(kParts);
}

void DiffusionAccumulator::serialize(Archive& a) {
  a.tag("diffusion_accumulator");
  vacf_.serialize(a);
  msd_.serialize(a);
  if (x_) msd_x_.serialize(a);
  coarse_.serialize(a);
  for (Interval& iv : intervals_) iv.c.serialize(a);
}

// D: every origin of the coarse samples, lags up to the end of the fit window if the data
// allow, else as far as they go.
void DiffusionAccumulator::fit_msd(DiffusionReport& r) const {
  const double dtc = r.coarse_strain;
  const double measured = static_cast<double>(r.samples - 1) * dt_;
  const long want = static_cast<long>(std::ceil(s_.window_hi / dtc - 1e-9)) + 1;
  const long max_lag = std::min({want, coarse_.samples() - 2, coarse_.band()});
  r.msd_coarse = coarse_.msd(dtc, max_lag);
  r.window_hi = std::min(s_.window_hi, static_cast<double>(max_lag) * dtc);
  // Only a window cut short by the data moves its start (to keep some points in it).
  r.window_lo =
      r.window_hi < s_.window_hi ? std::min(s_.window_lo, 0.5 * r.window_hi) : s_.window_lo;
  if (r.window_hi < s_.window_hi)
    r.warnings.push_back(fmt::format(
        "the measured window ({:.3g} strains) is shorter than the MSD fit window [{:g}, {:g}]: "
        "fitted over [{:.3g}, {:.3g}] instead",
        measured, s_.window_lo, s_.window_hi, r.window_lo, r.window_hi));
  r.fit = fit_diffusion(r.msd_coarse, r.window_lo, r.window_hi);
  if (std::isfinite(r.fit.loglog_slope) && std::abs(r.fit.loglog_slope - 1.0) > 0.2)
    r.warnings.push_back(
        fmt::format("the MSD is not diffusive in the fit window (log-log slope {:.3f}, 1 expected)",
                    r.fit.loglog_slope));
}

// The sample-resolution MSD, dv, Psi and the step length, with what limits their resolution.
void DiffusionAccumulator::velocities(DiffusionReport& r, long block_samples, long blocks) const {
  const long vacf_per_block = block_samples / vacf_.block();  // correlator blocks per block
  r.msd = msd_from(join_blocks(msd_, 1, 1, false), dt_, static_cast<double>(particles_));
  r.vel = persistence_from(join_blocks(vacf_, vacf_per_block, blocks, false), dt_);
  r.vacf = r.vel.c;
  r.persistence = r.vel.p;
  r.dv = r.vel.dv;
  r.step_length = r.dv * r.persistence.psi;
  r.consistency = r.fit.d / (r.dv * r.dv * r.persistence.psi);
  if (r.persistence.psi < 10.0 * dt_)
    r.warnings.push_back(fmt::format(
        "C(tau) is under-resolved: Psi = {:.3g} strain is less than 10 samples ({:g} strain "
        "each); lower analysis.sample_strain",
        r.persistence.psi, dt_));
  if (r.error_block < 10.0 * r.persistence.psi)
    r.warnings.push_back(fmt::format(
        "error-bar blocks of {:.3g} strain are shorter than 10 Psi = {:.3g}: the errors may be "
        "underestimated (measure longer)",
        r.error_block, 10.0 * r.persistence.psi));
}

// D's error bar from the same coarse samples, in blocks of the error-block length.
void DiffusionAccumulator::d_error_bar(DiffusionReport& r) const {
  try {
    const long bc = std::max(2L, std::lround(r.error_block / r.coarse_strain));
    r.d_error = msd_slope_error(coarse_, r.coarse_strain, r.window_lo, r.window_hi, bc);
  } catch (const std::invalid_argument& e) {
    r.d_error.d = r.d_error.err = std::nan("");
    r.warnings.push_back(fmt::format("no error bar for D: {}", e.what()));
  }
}

void DiffusionAccumulator::bulk_only(DiffusionReport& r, long block_samples, long blocks) const {
  const auto parts = static_cast<double>(particles_);
  const JoinedSums m = join_blocks(msd_, 1, 1, true);
  r.bulk_fraction = m.count.size() > 0 && m.count(0) > 0
                        ? m.count(0) / (parts * static_cast<double>(r.samples))
                        : 0.0;
  if (r.bulk_fraction <= 0.0) {
    r.warnings.push_back("no particle is ever in the bulk: no bulk-only analysis");
    return;
  }
  r.has_bulk = true;
  r.msd_bulk = msd_from(m, dt_, parts);
  try {
    r.fit_bulk = fit_diffusion(r.msd_bulk, r.window_lo, r.window_hi);
  } catch (const std::invalid_argument& e) {
    r.fit_bulk.d = std::nan("");
    r.warnings.push_back(fmt::format("no bulk D: {}", e.what()));
  }
  r.vel_bulk =
      persistence_from(join_blocks(vacf_, block_samples / vacf_.block(), blocks, true), dt_);
}

void DiffusionAccumulator::interval_velocities(DiffusionReport& r) const {
  for (const Interval& iv : intervals_) {
    DiffusionReport::IntervalVelocity out;
    out.sample_strain = static_cast<double>(1L << iv.level) * dt_;
    out.interval = static_cast<double>(iv.k) * out.sample_strain;
    if (iv.c.samples() < 4) {
      r.warnings.push_back(
          fmt::format("no velocity over {:g}: fewer than 4 samples", out.interval));
      continue;
    }
    const ErrorBlocks b = error_blocks(iv.c.samples(), iv.mini);
    out.vel = persistence_from(join_blocks(iv.c, b.block_samples / iv.c.block(), b.blocks, false),
                               out.sample_strain);
    r.intervals.push_back(out);
  }
}

void DiffusionAccumulator::x_diffusion(DiffusionReport& r) const {
  r.has_x = true;
  r.msd_x = msd_from(join_blocks(msd_x_, 1, 1, false), dt_, static_cast<double>(particles_));
  try {
    r.fit_x = fit_diffusion(r.msd_x, r.window_lo, r.window_hi);
  } catch (const std::invalid_argument& e) {
    r.fit_x.d = r.fit_x.loglog_slope = std::nan("");
    r.warnings.push_back(fmt::format("no x diffusion: {}", e.what()));
  }
}

DiffusionReport DiffusionAccumulator::report() const {
  DiffusionReport r;
  r.sample_strain = dt_;
  r.coarse_strain = static_cast<double>(stride_) * dt_;
  r.samples = samples();
  r.particles = particles_;
  const long coarse = coarse_.samples();
  if (r.samples < 4 || coarse < 4)
    throw std::invalid_argument(fmt::format(
        "diffusion analysis: {} samples ({} of them {:g} strain apart) of {} particles in the "
        "measured window; at least 4 of each are needed (run longer after steady state)",
        r.samples, coarse, r.coarse_strain, r.particles));
  fit_msd(r);
  const ErrorBlocks eb = error_blocks(r.samples, mini_);
  r.error_block = static_cast<double>(eb.block_samples) * dt_;
  if (r.error_block < 0.99 * s_.error_block)
    r.warnings.push_back(fmt::format(
        "error bars from {} blocks of {:.3g} strain (analysis.error_block = {:g} would leave "
        "fewer than 4 in the measured window)",
        eb.blocks, r.error_block, s_.error_block));
  velocities(r, eb.block_samples, eb.blocks);
  d_error_bar(r);
  if (bulk_) bulk_only(r, eb.block_samples, eb.blocks);
  interval_velocities(r);
  if (x_) x_diffusion(r);
  return r;
}

DiffusionReport analyse_diffusion(const Eigen::MatrixXd& y, const Eigen::MatrixXd& vy,
                                  double frame_strain, const DiffusionSettings& s,
                                  const Eigen::MatrixXd* bulk) {
  if (y.rows() != vy.rows() || y.cols() != vy.cols() ||
      (bulk && (bulk->rows() != y.rows() || bulk->cols() != y.cols())))
    throw std::invalid_argument("analyse_diffusion: y, vy and the bulk mask differ in shape");
  if (y.rows() < 4 || y.cols() < 1)
    throw std::invalid_argument(fmt::format(
        "diffusion analysis: {} frames of {} particles in the measured window; at least 4 frames "
        "are needed (run longer after steady state)",
        y.rows(), y.cols()));
  DiffusionAccumulator acc(s, frame_strain, static_cast<long>(y.cols()), bulk != nullptr, false);
  // Frames as contiguous rows, as the run hands its samples over.
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor yr = y, vr = vy;
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(y.cols()));
  for (Eigen::Index t = 0; t < y.rows(); ++t) {
    if (bulk)
      for (Eigen::Index i = 0; i < y.cols(); ++i)
        mask[static_cast<std::size_t>(i)] = (*bulk)(t, i) != 0.0 ? 1 : 0;
    acc.add(yr.row(t).data(), vr.row(t).data(), nullptr, bulk ? mask.data() : nullptr);
  }
  return acc.report();
}

void add_to_summary(const DiffusionReport& r, nlohmann::json& js) {
  js[summary_key::D] = r.fit.d;
  js[summary_key::D_err] = number_or_null(r.d_error.err);
  js[summary_key::D_regression_stderr] = r.fit.d_stderr;
  js[summary_key::D_all_reference_times] = number_or_null(r.d_error.d);
  js[summary_key::dv] = r.dv;
  js[summary_key::dv_err] = number_or_null(r.vel.dv_err);
  js[summary_key::psi] = r.persistence.psi;
  js[summary_key::psi_err] = number_or_null(r.vel.psi_err);
  js[summary_key::psi_e] = number_or_null(r.persistence.psi_e);
  js[summary_key::psi_e_err] = number_or_null(r.vel.psi_e_err);
  js[summary_key::psi_zero] = number_or_null(r.persistence.psi_zero);
  js[summary_key::psi_zero_err] = number_or_null(r.vel.psi_zero_err);
  js[summary_key::psi_full] = number_or_null(r.persistence.psi_full);
  js[summary_key::psi_full_err] = number_or_null(r.vel.psi_full_err);
  // D / dv^2: the persistence time a random walk with this D and dv would need.
  js[summary_key::psi_from_D] =
      r.dv > 0 ? nlohmann::json(r.fit.d / (r.dv * r.dv)) : nlohmann::json(nullptr);
  js[summary_key::step_length] = r.step_length;
  js[summary_key::diffusion_consistency] = r.consistency;
  js[summary_key::msd_window] = {r.window_lo, r.window_hi};
  js[summary_key::msd_window_slope] = number_or_null(r.fit.loglog_slope);
  js[summary_key::error_block_strain] = r.error_block;
  js[summary_key::error_blocks] = r.vel.blocks;
  if (r.has_bulk) {
    js[summary_key::bulk_fraction] = r.bulk_fraction;
    js[summary_key::D_bulk] = r.fit_bulk.d;
    js[summary_key::dv_bulk] = r.vel_bulk.dv;
    js[summary_key::dv_bulk_err] = number_or_null(r.vel_bulk.dv_err);
    js[summary_key::psi_bulk] = r.vel_bulk.p.psi;
    js[summary_key::psi_bulk_err] = number_or_null(r.vel_bulk.psi_err);
    js[summary_key::psi_e_bulk] = number_or_null(r.vel_bulk.p.psi_e);
    js[summary_key::psi_full_bulk] = number_or_null(r.vel_bulk.p.psi_full);
  }
  if (r.has_x) {
    js[summary_key::D_x] = number_or_null(r.fit_x.d);
    js[summary_key::msd_x_window_slope] = number_or_null(r.fit_x.loglog_slope);
  }
  if (!r.intervals.empty()) {
    auto& v = js[summary_key::velocity_intervals] = nlohmann::json::array();
    auto& dv = js[summary_key::dv_intervals] = nlohmann::json::array();
    auto& dv_err = js[summary_key::dv_intervals_err] = nlohmann::json::array();
    auto& psi = js[summary_key::psi_intervals] = nlohmann::json::array();
    auto& psi_err = js[summary_key::psi_intervals_err] = nlohmann::json::array();
    for (const auto& iv : r.intervals) {
      v.push_back(iv.interval);
      dv.push_back(iv.vel.dv);
      dv_err.push_back(number_or_null(iv.vel.dv_err));
      psi.push_back(iv.vel.p.psi);
      psi_err.push_back(number_or_null(iv.vel.psi_err));
    }
  }
  js[summary_key::analysis_samples] = r.samples;
  js[summary_key::analysis_sample_strain] = r.sample_strain;
  js[summary_key::analysis_coarse_strain] = r.coarse_strain;
  js[summary_key::analysis_warnings] = r.warnings;
}

}  // namespace sheardiff
