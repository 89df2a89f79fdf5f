#include "sheardiff/observe/analysis_file.hpp"

#include <fmt/format.h>

#include <stdexcept>

#include "sheardiff/io/hdf5_tables.hpp"
#include "sheardiff/io/summary_keys.hpp"

namespace sheardiff {

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
    write_vector(f, "/msd/lag", r.msd.lag, "1/gammadot",
                 "lag tau of the MSD, in strain (the multiple-tau grid of the samples)");
    write_vector(f, "/msd/msd", r.msd.msd, "d^2",
                 "mean square displacement in the gradient direction y over the mobile discs and "
                 "every origin on the lag's grid");
    write_vector(f, "/msd/samples", std::vector<double>(r.msd.samples.begin(), r.msd.samples.end()),
                 "1", "number of (disc, origin) pairs averaged at each lag, per disc");
    write_vector(f, "/msd_coarse/lag", r.msd_coarse.lag, "1/gammadot",
                 "lag tau of the coarse MSD (analysis.coarse_strain apart), in strain");
    write_vector(f, "/msd_coarse/msd", r.msd_coarse.msd, "d^2",
                 "the MSD in y over every origin of the coarse samples: the curve D is fitted to");
    if (r.has_x)
      write_vector(f, "/msd/msd_x", r.msd_x.msd, "d^2",
                   "MSD of the x displacement relative to the imposed flow (integrated step by "
                   "step), same lags as /msd/msd");
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
    write_attribute(root.id, summary_key::D, r.fit.d);
    write_attribute(root.id, summary_key::D_err, r.d_error.err);
    write_attribute(root.id, summary_key::D_regression_stderr, r.fit.d_stderr);
    write_attribute(root.id, "msd_intercept", r.fit.intercept);
    write_attribute(root.id, "msd_window_lo", r.window_lo);
    write_attribute(root.id, "msd_window_hi", r.window_hi);
    write_attribute(root.id, summary_key::msd_window_slope, r.fit.loglog_slope);
    write_attribute(root.id, summary_key::dv, r.dv);
    write_attribute(root.id, summary_key::psi, r.persistence.psi);
    write_attribute(root.id, summary_key::psi_e, r.persistence.psi_e);
    write_attribute(root.id, summary_key::psi_zero, r.persistence.psi_zero);
    write_attribute(root.id, summary_key::psi_full, r.persistence.psi_full);
    write_attribute(root.id, summary_key::psi_err, r.vel.psi_err);
    write_attribute(root.id, summary_key::dv_err, r.vel.dv_err);
    write_attribute(root.id, summary_key::step_length, r.step_length);
    write_attribute(root.id, "sample_strain", r.sample_strain);
    write_attribute(root.id, "coarse_strain", r.coarse_strain);
    if (H5Fflush(f, H5F_SCOPE_LOCAL) < 0) throw std::runtime_error("flush");
  } catch (const std::exception&) {
    H5Fclose(f);
    fail("write");
  }
  if (H5Fclose(f) < 0) fail("write");
  std::filesystem::rename(tmp, file);
}

}  // namespace sheardiff
