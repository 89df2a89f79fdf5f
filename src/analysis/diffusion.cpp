#include "sheardiff/analysis/diffusion.hpp"

#include <fmt/format.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sheardiff {

DiffusionReport analyse_diffusion(const Eigen::MatrixXd& y, const Eigen::MatrixXd& vy,
                                  double frame_strain, const DiffusionSettings& s) {
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
    r.warnings.push_back(fmt::format(
        "the MSD is not diffusive in the fit window (log-log slope {:.3f}, 1 expected)",
        r.fit.loglog_slope));

  r.dv = std::sqrt(vy.array().square().mean());
  const long vlag = std::min(static_cast<long>(std::ceil(s.vacf_max_lag / frame_strain)),
                             r.frames - 1);
  r.vacf = velocity_autocorrelation(vy, frame_strain, vlag);
  r.persistence = persistence_time(r.vacf);
  r.step_length = r.dv * r.persistence.psi;
  r.consistency = r.fit.d / (r.dv * r.dv * r.persistence.psi);
  if (r.persistence.psi < 10.0 * frame_strain)
    r.warnings.push_back(fmt::format(
        "C(tau) is under-resolved: Psi = {:.3g} strain is less than 10 frames ({:g} strain "
        "each); lower output.frame_strain",
        r.persistence.psi, frame_strain));
  return r;
}

void add_to_summary(const DiffusionReport& r, nlohmann::json& js) {
  js["D"] = r.fit.d;
  js["D_stderr"] = r.fit.d_stderr;
  js["dv"] = r.dv;
  js["psi"] = r.persistence.psi;
  js["psi_e"] = std::isfinite(r.persistence.psi_e) ? nlohmann::json(r.persistence.psi_e)
                                                   : nlohmann::json(nullptr);
  js["step_length"] = r.step_length;
  js["diffusion_consistency"] = r.consistency;
  js["msd_window"] = {r.window_lo, r.window_hi};
  js["msd_window_slope"] = std::isfinite(r.fit.loglog_slope) ? nlohmann::json(r.fit.loglog_slope)
                                                            : nlohmann::json(nullptr);
  js["analysis_frames"] = r.frames;
  js["analysis_frame_strain"] = r.frame_strain;
  js["analysis_reference_times"] = r.reference_times;
  js["analysis_warnings"] = r.warnings;
}

namespace {

struct H5 {
  hid_t id;
  herr_t (*close)(hid_t);
  ~H5() {
    if (id >= 0) close(id);
  }
};

void write_vector(hid_t file, const std::string& name, const std::vector<double>& v) {
  const hsize_t n = v.size();
  H5 space{H5Screate_simple(1, &n, nullptr), H5Sclose};
  H5 lcpl{H5Pcreate(H5P_LINK_CREATE), H5Pclose};
  H5Pset_create_intermediate_group(lcpl.id, 1);
  H5 ds{H5Dcreate2(file, name.c_str(), H5T_NATIVE_DOUBLE, space.id, lcpl.id, H5P_DEFAULT,
                   H5P_DEFAULT),
        H5Dclose};
  if (ds.id < 0 || H5Dwrite(ds.id, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()) < 0)
    throw std::runtime_error("analysis file: cannot write " + name);
}

void write_attr(hid_t obj, const char* name, double x) {
  H5 space{H5Screate(H5S_SCALAR), H5Sclose};
  H5 a{H5Acreate2(obj, name, H5T_NATIVE_DOUBLE, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
  H5Awrite(a.id, H5T_NATIVE_DOUBLE, &x);
}

}  // namespace

void write_analysis_file(const DiffusionReport& r, const std::filesystem::path& file) {
  // Written under a temporary name and renamed, so a complete-looking file is complete.
  const auto tmp = file.string() + ".tmp";
  {
    H5 f{H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose};
    if (f.id < 0) throw std::runtime_error("cannot create " + tmp);
    write_vector(f.id, "/msd/lag", r.msd.lag);
    write_vector(f.id, "/msd/msd", r.msd.msd);
    write_vector(f.id, "/msd/samples", std::vector<double>(r.msd.samples.begin(), r.msd.samples.end()));
    write_vector(f.id, "/vacf/lag", r.vacf.lag);
    write_vector(f.id, "/vacf/c", r.vacf.c);
    H5 root{H5Gopen2(f.id, "/", H5P_DEFAULT), H5Gclose};
    write_attr(root.id, "D", r.fit.d);
    write_attr(root.id, "D_stderr", r.fit.d_stderr);
    write_attr(root.id, "msd_intercept", r.fit.intercept);
    write_attr(root.id, "msd_window_lo", r.window_lo);
    write_attr(root.id, "msd_window_hi", r.window_hi);
    write_attr(root.id, "msd_window_slope", r.fit.loglog_slope);
    write_attr(root.id, "dv", r.dv);
    write_attr(root.id, "psi", r.persistence.psi);
    write_attr(root.id, "psi_e", r.persistence.psi_e);
    write_attr(root.id, "step_length", r.step_length);
    write_attr(root.id, "frame_strain", r.frame_strain);
  }
  std::filesystem::rename(tmp, file);
}

}  // namespace sheardiff
