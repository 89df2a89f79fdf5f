#include "sheardiff/observe/diffusion_observer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <sstream>

#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/io/text.hpp"
#include "sheardiff/observe/pressure_cell.hpp"
#include "sheardiff/scene/scene.hpp"
#include "sheardiff/version.hpp"

namespace sheardiff {

DiffusionSettings diffusion_settings(const Config& cfg) {
  DiffusionSettings s;
  s.window_lo = cfg.analysis.msd_window_lo;
  s.window_hi = cfg.analysis.msd_window_hi;
  s.reference_times = cfg.analysis.reference_times;
  s.vacf_max_lag = cfg.analysis.vacf_max_lag;
  s.error_block = cfg.analysis.error_block;
  s.seed = static_cast<std::uint64_t>(cfg.run.seed);
  return s;
}

DiffusionObserver::DiffusionObserver(const Config& cfg, std::filesystem::path analysis_file,
                                     std::function<bool(const Dynamics&)> measuring)
    : settings_(diffusion_settings(cfg)),
      frame_strain_(cfg.output.frame_strain),
      file_(std::move(analysis_file)),
      measuring_(std::move(measuring)),
      exclusion_(cfg.observables.wall_exclusion) {}

void DiffusionObserver::on_frame(const StepView& v, std::vector<double>&) {
  const Dynamics& d = v.dynamics;
  if (!measuring_(d)) return;
  const Particles& p = d.particles();
  const double gd = d.flow().gammadot;
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    y_.push_back(p.unwrapped[i].y());
    vy_.push_back(v.velocities.u[i].y() / gd);
  }
  if (d.walls()) {
    bottom_.push_back(mean_height(p, d.walls()->bottom));
    top_.push_back(mean_height(p, d.walls()->top));
  }
  ++frames_;
}

void DiffusionObserver::finish(const Dynamics& d, nlohmann::json& js, H5mdWriter*) {
  const auto n = static_cast<Eigen::Index>(d.particles().n_mobile);
  if (frames_ < 4) {
    js["analysis_warnings"] = {
        fmt::format("no diffusion analysis: only {} frames in the measured window", frames_)};
    return;
  }
  // Row-major buffers (one frame per row) mapped as frames x particles.
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::MatrixXd y = Eigen::Map<const RowMajor>(y_.data(), frames_, n);
  const Eigen::MatrixXd vy = Eigen::Map<const RowMajor>(vy_.data(), frames_, n);
  Eigen::MatrixXd mask;
  if (static_cast<long>(bottom_.size()) == frames_ && frames_ > 0)
    mask = bulk_mask(y, Eigen::Map<const Eigen::VectorXd>(bottom_.data(), frames_),
                     Eigen::Map<const Eigen::VectorXd>(top_.data(), frames_), exclusion_);
  try {
    const DiffusionReport r =
        analyse_diffusion(y, vy, frame_strain_, settings_, mask.size() ? &mask : nullptr);
    add_to_summary(r, js);
    if (!file_.empty()) write_analysis_file(r, file_);
  } catch (const std::invalid_argument& e) {
    // Too little data for the fits is a finding about the run, not a reason to lose it.
    js["analysis_warnings"] = {fmt::format("no diffusion analysis: {}", e.what())};
  }
}

namespace {

// The keys of `computed` merged into the run's summary: keys the run lacked are added, keys it
// has must come out equal (else they are listed in `differs`); warnings are joined.
nlohmann::json merge_analysis(const nlohmann::json& run, const nlohmann::json& computed,
                              std::vector<std::string>& differs) {
  nlohmann::json out = run;
  for (const auto& [key, value] : computed.items()) {
    if (key == "analysis_warnings") {
      nlohmann::json w = run.value("analysis_warnings", nlohmann::json::array());
      for (const auto& line : value)
        if (std::find(w.begin(), w.end(), line) == w.end()) w.push_back(line);
      out[key] = w;
      continue;
    }
    if (run.contains(key) && run[key] != value) differs.push_back(key);
    out[key] = value;
  }
  return out;
}

}  // namespace

Reanalysis reanalyse_run(const std::filesystem::path& dir,
                         const std::vector<std::string>& overrides) {
  const auto traj = dir / "trajectory.h5";
  for (const std::string& o : overrides)
    if (!o.starts_with("analysis.") && !o.starts_with("observables."))
      throw ConfigError(fmt::format(
          "analyse --set {}: only analysis.* and observables.* keys change an analysis of the "
          "same frames; the others change the run (run it again)",
          o));
  const Config cfg = load_config(dir / "config.toml", overrides);
  nlohmann::json run;
  {
    std::ifstream in(dir / "summary.json");
    if (!in)
      throw std::runtime_error(
          fmt::format("{}: no summary.json (run not finished?)", dir.string()));
    run = nlohmann::json::parse(in);
  }
  if (scene_kind(cfg.scene.type).channel_flow)
    throw ConfigError(fmt::format(
        "{}: a channel run has no diffusion analysis to recompute; its results are channel.h5 "
        "and summary.json, read by tools/channel_table.py",
        dir.string()));
  // The measured window: frames from the detection of steady state (pressure cell) or after
  // the transient (simple shear), the same test the observers applied while running.
  const bool pressure = scene_kind(cfg.scene.type).measured_from_steady_state;
  if (pressure && !run.value("steady", false))
    throw std::runtime_error(fmt::format("{}: the run never reached steady state", dir.string()));
  const double from = pressure ? run["steady_detected_at"].get<double>() : cfg.run.transient_strain;
  const ObservableSeries strain = read_h5md_observable(traj, "strain");
  std::vector<long> frames;
  for (std::size_t k = 0; k < strain.value.size(); ++k)
    if (pressure ? strain.value[k] >= from : strain.value[k] > from)
      frames.push_back(static_cast<long>(k));
  if (frames.size() < 4)
    throw std::runtime_error(
        fmt::format("{}: only {} frames in the measured window", dir.string(), frames.size()));
  // The run measured its profiles at every step; frames can only approximate them, so they are
  // computed here only for a run that has none (an older version's).
  const bool want_profiles = pressure && !run.contains("profile_phi");
  Eigen::MatrixXd y, vy;
  Eigen::VectorXd bottom(static_cast<Eigen::Index>(frames.size())), top(bottom.size());
  bool walls = false;
  GapProfiles profiles(cfg.observables.profile_bin);
  double height_sum = 0;
  for (std::size_t row = 0; row < frames.size(); ++row) {
    const H5mdFrame f = read_h5md_frame(traj, frames[row]);
    if (f.unwrapped.empty() || f.velocity.empty())
      throw std::runtime_error(
          fmt::format("{}: frames lack unwrapped positions or velocities "
                      "(output.velocities = false?)",
                      traj.string()));
    std::vector<std::size_t> mobile;
    for (std::size_t i = 0; i < f.position.size(); ++i)
      if (f.motion.empty() || f.motion[i] == 0) mobile.push_back(i);
    if (row == 0) {
      y.resize(static_cast<Eigen::Index>(frames.size()), static_cast<Eigen::Index>(mobile.size()));
      vy.resizeLike(y);
    }
    for (std::size_t c = 0; c < mobile.size(); ++c) {
      y(static_cast<Eigen::Index>(row), static_cast<Eigen::Index>(c)) = f.unwrapped[mobile[c]].y();
      vy(static_cast<Eigen::Index>(row), static_cast<Eigen::Index>(c)) =
          f.velocity[mobile[c]].y() / cfg.flow.j;
    }
    // Wall centre lines (fixed bottom, floating top) for the bulk-only analysis and profiles.
    double yb = 0, yt = 0;
    long nb = 0, nt = 0;
    for (std::size_t i = 0; i < f.motion.size(); ++i) {
      if (f.motion[i] == static_cast<int>(Motion::FixedWall)) yb += f.position[i].y(), ++nb;
      if (f.motion[i] == static_cast<int>(Motion::FloatingWall) ||
          f.motion[i] == static_cast<int>(Motion::DrivenWall))
        yt += f.position[i].y(), ++nt;
    }
    if (nb > 0 && nt > 0) {
      walls = true;
      const auto r = static_cast<Eigen::Index>(row);
      bottom(r) = yb / static_cast<double>(nb);
      top(r) = yt / static_cast<double>(nt);
      if (!want_profiles) continue;
      Particles p;
      p.n_mobile = mobile.size();
      std::vector<Vec3> u;
      for (std::size_t c = 0; c < mobile.size(); ++c) {
        p.position.push_back(f.position[mobile[c]]);
        p.radius.push_back(0.5 * f.diameter[mobile[c]]);
        u.push_back(f.velocity[mobile[c]]);
      }
      const double h = top(r) - bottom(r);
      height_sum += h;
      profiles.add(p, u, bottom(r), h, f.lx, 1.0);
    }
  }
  Eigen::MatrixXd mask;
  if (walls) mask = bulk_mask(y, bottom, top, cfg.observables.wall_exclusion);
  nlohmann::json computed;
  std::optional<DiffusionReport> r;
  try {
    r = analyse_diffusion(y, vy, cfg.output.frame_strain, diffusion_settings(cfg),
                          walls ? &mask : nullptr);
    add_to_summary(*r, computed);
  } catch (const std::invalid_argument& e) {
    // As in the run: too little data for the fits is a finding, the rest is still computed.
    computed["analysis_warnings"] = {fmt::format("no diffusion analysis: {}", e.what())};
  }
  if (pressure) {
    // The steady window's error bars and stationarity from the frames: the samples the run's
    // observer took (every frame from the detection of steady state on).
    const auto series = [&](const char* name) { return read_h5md_observable(traj, name).value; };
    const auto h = series("H"), mu_top = series("mu_top"), mu_bottom = series("mu_bottom");
    const double last = strain.value[static_cast<std::size_t>(frames.back())];
    add_steady_errors(computed, strain.value, h, series("phi"), mu_top, mu_bottom, from, last,
                      cfg.analysis.error_block);
    if (has_h5md_observable(traj, "net_drag_y"))
      add_stationarity(computed,
                       pressure_cell_stationarity(cfg.steady, strain.value, h, mu_top, mu_bottom,
                                                  series("net_drag_y"), series("bulk_normal_load"),
                                                  from, last, cfg.analysis.error_block));
    if (want_profiles && walls) {
      profiles.to_summary(computed, cfg.flow.j, height_sum / static_cast<double>(frames.size()),
                          cfg.observables.wall_exclusion);
      computed["profiles_from"] = "frames";
    }
  }
  Reanalysis out;
  out.summary = merge_analysis(run, computed, out.differs);
  // Nothing the run wrote is replaced: where the analysis disagrees with it (an older version's
  // numbers), the whole analysis goes beside the run's files.
  if (!overrides.empty()) out.summary["analysed_with"] = overrides;
  out.folder = out.differs.empty() && overrides.empty() ? dir : dir / "reanalysis";
  const bool summary_changes = out.summary != run;
  // The run's own version stays; the analysis says which code recomputed it.
  if (summary_changes) out.summary["analysed_by"] = version_line();
  const bool beside = out.folder != dir;
  if (beside) std::filesystem::create_directories(out.folder);
  if (r && (beside || !std::filesystem::exists(dir / "analysis.h5")))
    write_analysis_file(*r, out.folder / "analysis.h5");
  if (summary_changes || beside)
    write_file_atomically(out.folder / "summary.json", json_text(out.summary) + "\n");
  return out;
}

}  // namespace sheardiff
