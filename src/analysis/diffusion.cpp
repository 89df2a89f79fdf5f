#include "sheardiff/analysis/diffusion.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sheardiff/io/hdf5_tables.hpp"

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

DiffusionReport analyse_diffusion(const Eigen::MatrixXd& y, const Eigen::MatrixXd& vy,
                                  double frame_strain, const DiffusionSettings& s,
                                  const Eigen::MatrixXd* bulk) {
  DiffusionReport r;
  r.frame_strain = frame_strain;
  r.frames = y.rows();
  r.particles = y.cols();
  if (r.frames < 4 || r.particles < 1)
    throw std::invalid_argument(fmt::format(
        "diffusion analysis: {} frames of {} particles in the measured window; at least 4 frames "
        "are needed (run longer after steady state)",
        r.frames, r.particles));

  // MSD: lags up to the end of the fit window if the data allow, else as far as they go.
  const long want = static_cast<long>(std::ceil(s.window_hi / frame_strain)) + 1;
  const long max_lag = std::min(want, r.frames - 2);
  const auto t0 = draw_reference_frames(0, r.frames, max_lag, s.reference_times, s.seed);
  r.reference_times = static_cast<long>(t0.size());
  r.msd = mean_square_displacement(y, frame_strain, max_lag, t0);
  r.window_hi = std::min(s.window_hi, max_lag * frame_strain);
  // Only a window cut short by the data moves its start (to keep some points in it).
  r.window_lo = r.window_hi < s.window_hi ? std::min(s.window_lo, 0.5 * r.window_hi) : s.window_lo;
  if (r.window_hi < s.window_hi)
    r.warnings.push_back(fmt::format(
        "the measured window ({:.3g} strains) is shorter than the MSD fit window [{:g}, {:g}]: "
        "fitted over [{:.3g}, {:.3g}] instead",
        (r.frames - 1) * frame_strain, s.window_lo, s.window_hi, r.window_lo, r.window_hi));
  r.fit = fit_diffusion(r.msd, r.window_lo, r.window_hi);
  if (std::isfinite(r.fit.loglog_slope) && std::abs(r.fit.loglog_slope - 1.0) > 0.2)
    r.warnings.push_back(
        fmt::format("the MSD is not diffusive in the fit window (log-log slope {:.3f}, 1 expected)",
                    r.fit.loglog_slope));

  // Error bars: time blocks of s.error_block strain, at least 4 of them.
  const double measured = static_cast<double>(r.frames - 1) * frame_strain;
  r.error_block = std::min(s.error_block, measured / 4.0);
  if (r.error_block < s.error_block)
    r.warnings.push_back(fmt::format(
        "error bars from 4 blocks of {:.3g} strain (analysis.error_block = {:g} would leave "
        "fewer than 4 in the measured window)",
        r.error_block, s.error_block));
  const long vlag =
      std::min(static_cast<long>(std::ceil(s.vacf_max_lag / frame_strain)), r.frames - 1);
  const long block_frames = std::max(1L, std::lround(r.error_block / frame_strain));
  r.vel = persistence_with_errors(vy, frame_strain, vlag, block_frames);
  r.vacf = r.vel.c;
  r.persistence = r.vel.p;
  r.dv = r.vel.dv;
  r.step_length = r.dv * r.persistence.psi;
  r.consistency = r.fit.d / (r.dv * r.dv * r.persistence.psi);
  if (r.persistence.psi < 10.0 * frame_strain)
    r.warnings.push_back(fmt::format(
        "C(tau) is under-resolved: Psi = {:.3g} strain is less than 10 frames ({:g} strain "
        "each); lower output.frame_strain",
        r.persistence.psi, frame_strain));
  if (r.error_block < 10.0 * r.persistence.psi)
    r.warnings.push_back(fmt::format(
        "error-bar blocks of {:.3g} strain are shorter than 10 Psi = {:.3g}: the errors may be "
        "underestimated (measure longer)",
        r.error_block, 10.0 * r.persistence.psi));

  // D's error on frames ~0.05 strain apart (the MSD at lags of several strains needs no finer
  // ones; at most ~1500 frames keep the quadratic form's matrices small).
  long stride = std::max(1L, std::lround(0.05 / frame_strain));
  stride = std::max(stride, (r.frames - 1 + 1499) / 1500);
  {
    const long coarse_frames = (r.frames - 1) / stride + 1;
    Eigen::MatrixXd yc(coarse_frames, r.particles);
    for (long k = 0; k < coarse_frames; ++k) yc.row(k) = y.row(k * stride);
    const double dtc = frame_strain * static_cast<double>(stride);
    const long bc = std::max(2L, std::lround(r.error_block / dtc));
    try {
      r.d_error = msd_slope_error(yc, dtc, r.window_lo, r.window_hi, bc);
    } catch (const std::invalid_argument& e) {
      r.d_error.d = r.d_error.err = std::nan("");
      r.warnings.push_back(fmt::format("no error bar for D: {}", e.what()));
    }
  }

  if (bulk) {
    r.bulk_fraction = bulk->mean();
    if (r.bulk_fraction <= 0.0) {
      r.warnings.push_back("no disc is ever in the bulk: no bulk-only analysis");
    } else {
      r.has_bulk = true;
      r.msd_bulk = masked_mean_square_displacement(y, *bulk, frame_strain, max_lag, t0);
      r.fit_bulk = fit_diffusion(r.msd_bulk, r.window_lo, r.window_hi);
      r.vel_bulk = persistence_with_errors(vy, frame_strain, vlag, block_frames, bulk);
    }
  }
  return r;
}

void add_to_summary(const DiffusionReport& r, nlohmann::json& js) {
  js["D"] = r.fit.d;
  js["D_err"] = number_or_null(r.d_error.err);
  js["D_regression_stderr"] = r.fit.d_stderr;
  js["D_all_reference_times"] = number_or_null(r.d_error.d);
  js["dv"] = r.dv;
  js["dv_err"] = number_or_null(r.vel.dv_err);
  js["psi"] = r.persistence.psi;
  js["psi_err"] = number_or_null(r.vel.psi_err);
  js["psi_e"] = number_or_null(r.persistence.psi_e);
  js["psi_e_err"] = number_or_null(r.vel.psi_e_err);
  js["psi_zero"] = number_or_null(r.persistence.psi_zero);
  js["psi_zero_err"] = number_or_null(r.vel.psi_zero_err);
  js["psi_full"] = number_or_null(r.persistence.psi_full);
  js["psi_full_err"] = number_or_null(r.vel.psi_full_err);
  // D / dv^2: the persistence time a random walk with this D and dv would need.
  js["psi_from_D"] = r.dv > 0 ? nlohmann::json(r.fit.d / (r.dv * r.dv)) : nlohmann::json(nullptr);
  js["step_length"] = r.step_length;
  js["diffusion_consistency"] = r.consistency;
  js["msd_window"] = {r.window_lo, r.window_hi};
  js["msd_window_slope"] = number_or_null(r.fit.loglog_slope);
  js["error_block_strain"] = r.error_block;
  js["error_blocks"] = r.vel.blocks;
  if (r.has_bulk) {
    js["bulk_fraction"] = r.bulk_fraction;
    js["D_bulk"] = r.fit_bulk.d;
    js["dv_bulk"] = r.vel_bulk.dv;
    js["dv_bulk_err"] = number_or_null(r.vel_bulk.dv_err);
    js["psi_bulk"] = r.vel_bulk.p.psi;
    js["psi_bulk_err"] = number_or_null(r.vel_bulk.psi_err);
    js["psi_e_bulk"] = number_or_null(r.vel_bulk.p.psi_e);
    js["psi_full_bulk"] = number_or_null(r.vel_bulk.p.psi_full);
  }
  js["analysis_frames"] = r.frames;
  js["analysis_frame_strain"] = r.frame_strain;
  js["analysis_reference_times"] = r.reference_times;
  js["analysis_warnings"] = r.warnings;
}

void write_analysis_file(const DiffusionReport& r, const std::filesystem::path& file) {
  // Written under a temporary name and renamed, so a complete-looking file is complete; a
  // failed write (a full disk) removes the temporary file.
  const auto tmp = file.string() + ".tmp";
  const auto fail = [&](const std::string& what) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(fmt::format("cannot {} {}", what, file.string()));
  };
  const hid_t f = H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (f < 0) fail("create");
  try {
    // Units and descriptions as docs/outputs.md gives them.
    write_vector(f, "/msd/lag", r.msd.lag, "1/gammadot", "lag tau of the MSD, in strain");
    write_vector(f, "/msd/msd", r.msd.msd, "d^2",
                 "mean square displacement in the gradient direction y over the mobile discs and "
                 "the reference times");
    write_vector(f, "/msd/samples", std::vector<double>(r.msd.samples.begin(), r.msd.samples.end()),
                 "1", "number of (disc, reference time) pairs averaged at each lag");
    write_vector(f, "/vacf/lag", r.vacf.lag, "1/gammadot", "lag tau of the VACF, in strain");
    write_vector(f, "/vacf/c", r.vacf.c, "(gammadot d)^2",
                 "velocity autocorrelation <v_y(t0) v_y(t0 + tau)> of the mobile discs, not "
                 "normalised: C(0) = dv^2");
    if (r.has_bulk) {
      write_vector(f, "/msd/msd_bulk", r.msd_bulk.msd, "d^2",
                   "the MSD over discs in the bulk at the reference time (observables."
                   "wall_exclusion inside both walls)");
      write_vector(f, "/vacf/c_bulk", r.vel_bulk.c.c, "(gammadot d)^2",
                   "the VACF over origins in the bulk");
    }
    H5Id root{H5Gopen2(f, "/", H5P_DEFAULT), H5Gclose};
    write_attribute(root.id, "D", r.fit.d);
    write_attribute(root.id, "D_err", r.d_error.err);
    write_attribute(root.id, "D_regression_stderr", r.fit.d_stderr);
    write_attribute(root.id, "msd_intercept", r.fit.intercept);
    write_attribute(root.id, "msd_window_lo", r.window_lo);
    write_attribute(root.id, "msd_window_hi", r.window_hi);
    write_attribute(root.id, "msd_window_slope", r.fit.loglog_slope);
    write_attribute(root.id, "dv", r.dv);
    write_attribute(root.id, "psi", r.persistence.psi);
    write_attribute(root.id, "psi_e", r.persistence.psi_e);
    write_attribute(root.id, "psi_zero", r.persistence.psi_zero);
    write_attribute(root.id, "psi_full", r.persistence.psi_full);
    write_attribute(root.id, "psi_err", r.vel.psi_err);
    write_attribute(root.id, "dv_err", r.vel.dv_err);
    write_attribute(root.id, "step_length", r.step_length);
    write_attribute(root.id, "frame_strain", r.frame_strain);
    if (H5Fflush(f, H5F_SCOPE_LOCAL) < 0) throw std::runtime_error("flush");
  } catch (const std::exception&) {
    H5Fclose(f);
    fail("write");
  }
  if (H5Fclose(f) < 0) fail("write");
  std::filesystem::rename(tmp, file);
}

}  // namespace sheardiff
