#include "sheardiff/observe/diffusion_observer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <sstream>

#include "sheardiff/core/output_schedule.hpp"
#include "sheardiff/core/text.hpp"
#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/io/run_files.hpp"
#include "sheardiff/io/summary_keys.hpp"
#include "sheardiff/observe/analysis_file.hpp"
#include "sheardiff/observe/pressure_cell.hpp"
#include "sheardiff/scene/scene.hpp"
#include "sheardiff/version.hpp"

namespace sheardiff {

DiffusionSettings diffusion_settings(const Config& cfg) {
  DiffusionSettings s;
  s.window_lo = cfg.analysis.msd_window_lo;
  s.window_hi = cfg.analysis.msd_window_hi;
  s.vacf_max_lag = cfg.analysis.vacf_max_lag;
  s.error_block = cfg.analysis.error_block;
  s.coarse_strain = cfg.analysis.coarse_strain;
  s.velocity_intervals = cfg.analysis.velocity_intervals;
  return s;
}

template <class D>
DiffusionObserverOf<D>::DiffusionObserverOf(const Config& cfg, std::filesystem::path analysis_file,
                                            MeasuredWindowOf<D> measuring)
    : settings_(diffusion_settings(cfg)),
      sample_strain_(cfg.analysis.sample_strain),
      next_sample_(cfg.analysis.sample_strain),
      file_(std::move(analysis_file)),
      measuring_(std::move(measuring)),
      exclusion_(cfg.observables.wall_exclusion) {}

template <class D>
void DiffusionObserverOf<D>::on_step(const StepView& v) {
  const Dynamics& d = v.dynamics;
  const bool measuring = measuring_(d);
  const auto& p = d.particles();
  // The x displacement relative to the imposed flow, integrated over every step of the window.
  if (measuring && particles_ > 0)
    for (std::size_t i = 0; i < p.n_mobile; ++i)
      x_[i] += (v.velocities.u[i].x() - d.flow().velocity(p.position[i]).x()) * v.dt;
  // Samples are due on the same grid as frames (the first step at or past each mark).
  if (!output_due(next_sample_, d.strain())) return;
  const double next = next_output_strain(next_sample_, sample_strain_, d.strain());
  const long marks = std::lround((next - next_sample_) / sample_strain_);
  next_sample_ = next;
  if (!measuring) {
    // The pressure cell opens its window in on_frame (steady state detected at a frame): a
    // sample due at this step is taken there, once the window is open.
    due_at_step_ = d.steps();
    return;
  }
  if (particles_ > 0) skipped_ += std::max(0L, marks - 1);
  take_sample(v);
}

template <class D>
void DiffusionObserverOf<D>::on_frame(const StepView& v, std::vector<double>&) {
  if (due_at_step_ != v.dynamics.steps() || !measuring_(v.dynamics)) return;
  due_at_step_ = -1;
  take_sample(v);
}

template <class D>
void DiffusionObserverOf<D>::take_sample(const StepView& v) {
  const Dynamics& d = v.dynamics;
  const auto& p = d.particles();
  if (particles_ == 0) {
    particles_ = static_cast<long>(p.n_mobile);
    walls_ = d.walls().has_value();
    acc_ = DiffusionAccumulator(settings_, sample_strain_, particles_, walls_, true);
    x_.assign(p.n_mobile, 0.0);
  }
  const auto n = static_cast<std::size_t>(particles_);
  y_.resize(n), vy_.resize(n), bulk_.resize(n);
  const double gd = d.flow().gammadot;
  for (std::size_t i = 0; i < n; ++i) {
    y_[i] = p.unwrapped[i].y();
    vy_[i] = v.velocities.u[i].y() / gd;
  }
  if (walls_) {
    // As bulk_mask does with the frames' wall centre lines.
    const double bottom = mean_height(p, d.walls()->bottom);
    const double top = mean_height(p, d.walls()->top);
    for (std::size_t i = 0; i < n; ++i)
      bulk_[i] = y_[i] >= bottom + exclusion_ && y_[i] <= top - exclusion_ ? 1 : 0;
  }
  acc_.add(y_.data(), vy_.data(), x_.data(), walls_ ? bulk_.data() : nullptr);
}

template <class D>
void DiffusionObserverOf<D>::serialize(Archive& a) {
  a.tag("diffusion_samples");
  a.io(next_sample_), a.io(particles_), a.io(walls_), a.io(skipped_), a.io(x_);
  if (a.loading() && particles_ > 0)
    acc_ = DiffusionAccumulator(settings_, sample_strain_, particles_, walls_, true);
  if (particles_ > 0) acc_.serialize(a);
}

template <class D>
void DiffusionObserverOf<D>::finish(const Dynamics&, nlohmann::json& js, H5mdWriter*) {
  try {
    if (particles_ == 0) throw std::invalid_argument("no sample was taken in the measured window");
    DiffusionReport r = acc_.report();
    if (skipped_ > 0)
      r.warnings.push_back(fmt::format(
          "{} of {} sample marks fell in a step that already crossed one: the samples are "
          "further apart than analysis.sample_strain = {:g} there; raise it above the step's "
          "strain",
          skipped_, skipped_ + r.samples, sample_strain_));
    add_to_summary(r, js);
    if (!file_.empty()) write_analysis_file(r, file_);
  } catch (const std::invalid_argument& e) {
    // Too little data for the fits is a finding about the run, not a reason to lose it.
    js[summary_key::analysis_warnings] = {fmt::format("no diffusion analysis: {}", e.what())};
  }
}

template class DiffusionObserverOf<Dim2>;
template class DiffusionObserverOf<Dim3>;

namespace {

// The keys of `computed` merged into the run's summary: keys the run lacked are added, keys it
// has must come out equal (else they are listed in `differs`); warnings are joined.
nlohmann::json merge_analysis(const nlohmann::json& run, const nlohmann::json& computed,
                              std::vector<std::string>& differs) {
  nlohmann::json out = run;
  for (const auto& [key, value] : computed.items()) {
    if (key == summary_key::analysis_warnings) {
      nlohmann::json w = run.value(summary_key::analysis_warnings, nlohmann::json::array());
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

namespace {

// The run's finished summary.
nlohmann::json read_summary(const std::filesystem::path& dir) {
  std::ifstream in(dir / "summary.json");
  if (!in)
    throw std::runtime_error(fmt::format("{}: no summary.json (run not finished?)", dir.string()));
  return nlohmann::json::parse(in);
}

// The measured window's frames of a trajectory, as the observers saw them while running: the
// mobile discs' unwrapped y and v_y / gammadot, the walls' centre lines and, if asked, the gap
// profiles.
struct WindowFrames {
  Eigen::MatrixXd y, vy;
  Eigen::VectorXd bottom, top;
  bool walls = false;
  GapProfiles profiles;
  double height_sum = 0;
  explicit WindowFrames(double bin) : profiles(bin) {}
};

WindowFrames read_window(const std::filesystem::path& traj, const std::vector<long>& frames,
                         const Config& cfg, bool want_profiles) {
  WindowFrames w(cfg.observables.profile_bin);
  w.bottom.resize(static_cast<Eigen::Index>(frames.size()));
  w.top.resize(w.bottom.size());
  for (std::size_t row = 0; row < frames.size(); ++row) {
    const auto r = static_cast<Eigen::Index>(row);
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
      w.y.resize(static_cast<Eigen::Index>(frames.size()),
                 static_cast<Eigen::Index>(mobile.size()));
      w.vy.resizeLike(w.y);
    }
    for (std::size_t c = 0; c < mobile.size(); ++c) {
      w.y(r, static_cast<Eigen::Index>(c)) = f.unwrapped[mobile[c]].y();
      w.vy(r, static_cast<Eigen::Index>(c)) = f.velocity[mobile[c]].y() / cfg.flow.j;
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
    if (nb == 0 || nt == 0) continue;
    w.walls = true;
    w.bottom(r) = yb / static_cast<double>(nb);
    w.top(r) = yt / static_cast<double>(nt);
    if (!want_profiles) continue;
    Particles p;
    p.n_mobile = mobile.size();
    std::vector<Vec3> u;
    for (std::size_t c = 0; c < mobile.size(); ++c) {
      p.position.push_back(f.position[mobile[c]]);
      p.radius.push_back(0.5 * f.diameter[mobile[c]]);
      u.push_back(f.velocity[mobile[c]]);
    }
    const double h = w.top(r) - w.bottom(r);
    w.height_sum += h;
    w.profiles.add(p, u, w.bottom(r), h, f.lx, 1.0);
  }
  return w;
}

// The pressure cell's window keys from the frames' observables: the error bars and the
// stationarity signals over the samples the run's observer took (every frame from the
// detection of steady state on).
void add_window_keys(const std::filesystem::path& traj, const Config& cfg,
                     const std::vector<double>& strain, double from, double last,
                     nlohmann::json& computed) {
  const auto series = [&](const char* name) { return read_h5md_observable(traj, name).value; };
  // A run of an older sheardiff wrote no stationarity signals: its window has no verdict.
  const bool signals = has_h5md_observable(traj, "net_drag_y");
  const BinnedSeries window =
      cell_window(strain, series("H"), series("phi"), series("mu_top"), series("mu_bottom"),
                  signals ? series("net_drag_y") : std::vector<double>{},
                  signals ? series("bulk_normal_load") : std::vector<double>{}, from, last);
  add_steady_errors(computed, window, from, last, cfg.analysis.error_block);
  add_window_blocks(computed, window, from, last, cfg.analysis.error_block);
  if (signals)
    add_stationarity(computed, pressure_cell_stationarity(cfg.steady, window, from, last,
                                                          cfg.analysis.error_block));
}

// Writes what analyse found: nothing of the run's is replaced. Where the analysis disagrees
// with it (an older version's numbers) or was asked for other settings, the whole analysis
// goes beside the run's files.
Reanalysis write_reanalysis(const std::filesystem::path& dir, const nlohmann::json& run,
                            const nlohmann::json& computed,
                            const std::optional<DiffusionReport>& report,
                            const std::vector<std::string>& overrides) {
  Reanalysis out;
  out.summary = merge_analysis(run, computed, out.differs);
  if (!overrides.empty()) out.summary[summary_key::analysed_with] = overrides;
  out.folder = out.differs.empty() && overrides.empty() ? dir : dir / "reanalysis";
  const bool summary_changes = out.summary != run;
  // The run's own version stays; the analysis says which code recomputed it.
  if (summary_changes) out.summary[summary_key::analysed_by] = version_line();
  const bool beside = out.folder != dir;
  if (beside) std::filesystem::create_directories(out.folder);
  if (report && (beside || !std::filesystem::exists(dir / kAnalysisFile)))
    write_analysis_file(*report, out.folder / kAnalysisFile);
  if (summary_changes || beside)
    write_file_atomically(out.folder / "summary.json", json_text(out.summary) + "\n");
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
  const Config cfg = load_config(dir / "config.toml", overrides, ConfigSource::record);
  const nlohmann::json run = read_summary(dir);
  if (!scene_kind(cfg.scene.type).imposes_shear_rate())
    throw ConfigError(fmt::format(
        "{}: a channel run has no diffusion analysis to recompute; its results are channel.h5 "
        "and summary.json, read by tools/channel_table.py",
        dir.string()));
  // The measured window: frames from the detection of steady state (pressure cell) or after
  // the transient (simple shear), the same test the observers applied while running.
  const bool pressure = scene_kind(cfg.scene.type).measured_from_steady_state();
  if (pressure && !run.value(summary_key::steady, false))
    throw std::runtime_error(fmt::format("{}: the run never reached steady state", dir.string()));
  const double from =
      pressure ? run[summary_key::steady_detected_at].get<double>() : cfg.run.transient_strain;
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
  // (A run of spheres always measured its own; the frames' profiles are of discs.)
  const bool want_profiles =
      pressure && cfg.scene.dimension == 2 && !run.contains(summary_key::profile_phi);
  WindowFrames w = read_window(traj, frames, cfg, want_profiles);
  Eigen::MatrixXd mask;
  if (w.walls) mask = bulk_mask(w.y, w.bottom, w.top, cfg.observables.wall_exclusion);
  nlohmann::json computed;
  std::optional<DiffusionReport> report;
  try {
    report = analyse_diffusion(w.y, w.vy, cfg.output.frame_strain, diffusion_settings(cfg),
                               w.walls ? &mask : nullptr);
    add_to_summary(*report, computed);
  } catch (const std::invalid_argument& e) {
    // As in the run: too little data for the fits is a finding, the rest is still computed.
    computed[summary_key::analysis_warnings] = {fmt::format("no diffusion analysis: {}", e.what())};
  }
  if (pressure) {
    add_window_keys(traj, cfg, strain.value, from,
                    strain.value[static_cast<std::size_t>(frames.back())], computed);
    if (want_profiles && w.walls) {
      w.profiles.to_summary(computed, cfg.flow.j, w.height_sum / static_cast<double>(frames.size()),
                            cfg.observables.wall_exclusion);
      computed[summary_key::profiles_from] = "frames";
    }
  }
  return write_reanalysis(dir, run, computed, report, overrides);
}

}  // namespace sheardiff
