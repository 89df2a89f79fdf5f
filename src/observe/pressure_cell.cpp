#include "sheardiff/observe/pressure_cell.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "sheardiff/analysis/power_law.hpp"
#include "sheardiff/analysis/uncertainty.hpp"
#include "sheardiff/integrator/stress.hpp"
#include "sheardiff/io/h5md.hpp"
#include "sheardiff/io/summary_keys.hpp"

namespace sheardiff {

namespace {

constexpr long kMinWindowFrames = 8;

}  // namespace

void add_cell_sample(BinnedSeries& window, double strain, double h, double phi, double mu_top,
                     double mu_bottom, double net_drag_y, double bulk_load) {
  window.add(strain, {h, phi, mu_top, mu_bottom, 0.5 * (mu_top + mu_bottom), mu_top - mu_bottom,
                      net_drag_y, bulk_load});
}

BinnedSeries cell_window(const std::vector<double>& strain, const std::vector<double>& h,
                         const std::vector<double>& phi, const std::vector<double>& mu_top,
                         const std::vector<double>& mu_bottom,
                         const std::vector<double>& net_drag_y,
                         const std::vector<double>& bulk_load, double from, double to) {
  const std::size_t n = strain.size();
  const auto fits = [&](const std::vector<double>& v) { return v.empty() || v.size() == n; };
  if (h.size() != n || mu_top.size() != n || mu_bottom.size() != n || !fits(phi) ||
      !fits(net_drag_y) || !fits(bulk_load))
    throw std::invalid_argument("cell_window: the signals' lengths differ from the strains'");
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  const auto at = [](const std::vector<double>& v, std::size_t k) {
    return v.empty() ? kNone : v[k];
  };
  BinnedSeries w(CellSignal::count, kCellWindowBins);
  for (std::size_t k = 0; k < n; ++k)
    if (strain[k] >= from && strain[k] <= to)
      add_cell_sample(w, strain[k], h[k], at(phi, k), mu_top[k], mu_bottom[k], at(net_drag_y, k),
                      at(bulk_load, k));
  return w;
}

void add_steady_errors(nlohmann::json& js, const BinnedSeries& window, double from, double to,
                       double block) {
  const long n = to > from ? window.samples() : 0;
  if (n < kMinWindowFrames) {
    // Said rather than printed as "+- nan": too few frames to form blocks from.
    js[summary_key::steady_errors_note] = fmt::format(
        "no error bars: {} frames in the measured window, {} needed (lower output.frame_strain "
        "or measure longer)",
        n, kMinWindowFrames);
    return;
  }
  const long blocks = std::max(4L, static_cast<long>((to - from) / block));
  const auto err = [&](std::size_t signal) {
    const double e = batch_means(window, signal, from, to, blocks).err;
    return std::isfinite(e) ? nlohmann::json(e) : nlohmann::json(nullptr);
  };
  js[summary_key::H_err] = err(CellSignal::h);
  js[summary_key::phi_err] = err(CellSignal::phi);
  js[summary_key::mu_err] = err(CellSignal::mu);
  js[summary_key::mu_top_err] = err(CellSignal::mu_top);
  js[summary_key::mu_bottom_err] = err(CellSignal::mu_bottom);
}

StationarityVerdict pressure_cell_stationarity(const SteadyStateParams& cfg,
                                               const BinnedSeries& window, double from, double to,
                                               double block) {
  StationarityVerdict v;
  if (!(to > from) || window.samples() < kMinWindowFrames) return v;
  const long blocks = std::max(4L, static_cast<long>((to - from) / block));
  const auto means = [&](std::size_t signal) {
    return batch_means(window, signal, from, to, blocks);
  };
  const double z = cfg.drift_z;
  v.signals.push_back(
      mean_within_noise(summary_key::net_drag_y, means(CellSignal::net_drag_y), 0.0, z));
  v.signals.push_back(mean_within_noise(summary_key::mu_top_minus_bottom,
                                        means(CellSignal::mu_difference), 0.0, z));
  v.signals.push_back(
      trend_within_noise(summary_key::H_change, means(CellSignal::h), from, to, blocks, z));
  v.signals.push_back(mean_within_tolerance(
      summary_key::bulk_normal_load, means(CellSignal::bulk_load), 1.0, cfg.bulk_load_tolerance));
  return v;
}

void add_window_blocks(nlohmann::json& js, const BinnedSeries& window, double from, double to,
                       double block) {
  if (!(to > from) || window.samples() < kMinWindowFrames) return;
  const long blocks = std::max(4L, static_cast<long>((to - from) / block));
  const double width = (to - from) / static_cast<double>(blocks);
  std::vector<double> mid(static_cast<std::size_t>(blocks));
  for (long k = 0; k < blocks; ++k)
    mid[static_cast<std::size_t>(k)] = from + (static_cast<double>(k) + 0.5) * width;
  nlohmann::json out;
  out["strain"] = mid;
  const std::pair<const char*, std::size_t> signals[] = {
      {"H", CellSignal::h},
      {"phi", CellSignal::phi},
      {"mu", CellSignal::mu},
      {"mu_top_minus_bottom", CellSignal::mu_difference},
      {"net_drag_y", CellSignal::net_drag_y},
      {"bulk_normal_load", CellSignal::bulk_load}};
  for (const auto& [name, s] : signals) {
    const BatchMeans b = batch_means(window, s, from, to, blocks);
    // batch_means leaves out blocks without values: the means then no longer line up with the
    // strains, so the signal is null rather than shifted.
    out[name] = b.blocks == blocks ? nlohmann::json(b.block_means) : nlohmann::json(nullptr);
  }
  js[summary_key::window_blocks] = out;
}

void add_stationarity(nlohmann::json& js, const StationarityVerdict& v) {
  const auto num = [](double x) {
    return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
  };
  js[summary_key::stationary] = v.stationary();
  js[summary_key::not_stationary] =
      v.signals.empty() ? std::string("window too short") : v.failed();
  for (const DriftSignal& s : v.signals) {
    js[s.name] = num(s.expected + s.value);
    js[s.name + "_err"] = num(s.err);
  }
  if (!v.stationary())
    js[summary_key::stationarity_warning] = fmt::format(
        "the measured window is not stationary ({}): its averages describe a transient; run "
        "longer or start nearer the steady state (docs/model.md, \"Steady state\")",
        js[summary_key::not_stationary].get<std::string>());
}

namespace {

// The bulk band: wall_exclusion inside each wall's centre line, or the whole gap of a thin cell.
template <class D>
std::pair<double, double> bulk_band(const DynamicsOf<D>& d, double exclusion) {
  const auto& p = d.particles();
  const double yb = mean_height(p, d.walls()->bottom), yt = mean_height(p, d.walls()->top);
  double y1 = yb + exclusion, y2 = yt - exclusion;
  if (y2 - y1 < 1.0) y1 = yb, y2 = yt;
  return {y1, y2};
}

}  // namespace

template <class D>
PressureCellObserverOf<D>::PressureCellObserverOf(const Config& cfg)
    : steady_cfg_(cfg.steady),
      exclusion_(cfg.observables.wall_exclusion),
      pressure_(1.0),
      lz_(cfg.flow.lz),
      run_strain_(cfg.run.strain),
      error_block_(cfg.analysis.error_block) {}

template <class D>
double PressureCellObserverOf<D>::bulk_phi(const Dynamics& d, double exclusion) {
  const auto& p = d.particles();
  const auto [y1, y2] = bulk_band(d, exclusion);
  double taken = 0.0;
  for (std::size_t i = 0; i < p.n_mobile; ++i)
    taken += measure_between<D>(p.position[i].y(), p.radius[i], y1, y2);
  return taken / (band_section(d) * (y2 - y1));
}

template <class D>
std::vector<std::string> PressureCellObserverOf<D>::frame_names() const {
  return {"H",
          "phi",
          "mu_top",
          "mu_bottom",
          "pressure_measured",
          "wall_velocity_y",
          "net_drag_y",
          "bulk_normal_load"};
}

template <class D>
std::vector<std::string> PressureCellObserverOf<D>::frame_units() const {
  return {"d", "1", "1", "1", "P", "P d eta-1", "P", "P"};
}

template <class D>
void PressureCellObserverOf<D>::on_frame(const StepView& v, std::vector<double>& values) {
  const Dynamics& d = v.dynamics;
  const double a = horizontal_area(d, lz_);
  const double mu_top = -v.stress.top_wall_fx / a / pressure_;
  const double h = d.height(), phi = bulk_phi(d, exclusion_);
  const double mu_bottom = v.stress.bottom_wall_fx / a / pressure_;
  // The walls' load difference is the y drag of the fluid on the discs: positive when they sink.
  const double drag = (v.stress.top_wall_fy + v.stress.bottom_wall_fy) / a / pressure_;
  const auto [y1, y2] = bulk_band(d, exclusion_);
  const double load = normal_load_between(d, v.stages, y1, y2, lz_) / pressure_;
  values.insert(values.end(), {h, phi, mu_top, mu_bottom, v.stress.top_wall_fy / a,
                               v.velocities.wall_v, drag, load});
  // The measured window's frames: from the one at which steady state is detected on, the
  // frames the diffusion analysis and `sheardiff analyse` use.
  const auto sample = [&] {
    add_cell_sample(window_, d.strain(), h, phi, mu_top, mu_bottom, drag, load);
  };
  if (steady()) return sample();
  // The packing at rest before the first step is not yet sheared: no sample for the test.
  if (d.steps() == 0) return;
  hist_strain_.push_back(d.strain());
  hist_h_.push_back(h);
  hist_mu_.push_back(mu_top);
  const double now = d.strain();
  if (now - hist_strain_.front() < steady_cfg_.window) return;
  // Means of H and mu over the two halves of the last window.
  const double start = now - steady_cfg_.window, mid = now - 0.5 * steady_cfg_.window;
  // Frames older than the window are never read again: dropped, but for the first, whose strain
  // says how long the history is.
  const auto old_end = std::find_if(hist_strain_.begin() + 1, hist_strain_.end(),
                                    [&](double s) { return s >= start; });
  const auto dropped = old_end - (hist_strain_.begin() + 1);
  if (dropped > 0)
    for (auto* v : {&hist_strain_, &hist_h_, &hist_mu_})
      v->erase(v->begin() + 1, v->begin() + 1 + dropped);
  double h1 = 0, h2 = 0, m1 = 0, m2 = 0;
  int n1 = 0, n2 = 0;
  for (std::size_t k = 0; k < hist_strain_.size(); ++k) {
    if (hist_strain_[k] < start) continue;
    if (hist_strain_[k] < mid)
      h1 += hist_h_[k], m1 += hist_mu_[k], ++n1;
    else
      h2 += hist_h_[k], m2 += hist_mu_[k], ++n2;
  }
  if (n1 < 2 || n2 < 2) return;
  h1 /= n1, h2 /= n2, m1 /= n1, m2 /= n2;
  if (std::abs(h2 - h1) <= steady_cfg_.h_tolerance * 0.5 * (h1 + h2) &&
      std::abs(m2 - m1) <= steady_cfg_.mu_tolerance) {
    steady_at_ = now;
    steady_from_ = start;
    sample();
  }
}

template <class D>
void PressureCellObserverOf<D>::on_step(const StepView& v) {
  const Dynamics& d = v.dynamics;
  const double a = horizontal_area(d, lz_);
  if (v.velocities.wall_free_fall)
    ++free_fall_steps_;
  else
    max_p_err_ = std::max(max_p_err_, std::abs(v.stress.top_wall_fy / a - pressure_) / pressure_);
  if (!steady()) return;
  const double w = v.dt;
  const double phi = bulk_phi(d, exclusion_);
  w_ += w;
  h_ += w * d.height();
  phi_ += w * phi;
  phi2_ += w * phi * phi;
  mu_top_ += w * (-v.stress.top_wall_fx / a / pressure_);
  mu_bottom_ += w * (v.stress.bottom_wall_fx / a / pressure_);
  p_meas_ += w * v.stress.top_wall_fy / a;
}

template <class D>
double PressureCellObserverOf<D>::planned_end_strain() const {
  if (steady() && steady_cfg_.measure_strain > 0.0) return steady_at_ + steady_cfg_.measure_strain;
  return ObserverOf<D>::planned_end_strain();
}

template <class D>
bool PressureCellObserverOf<D>::done(const Dynamics& d) const {
  return steady() && steady_cfg_.measure_strain > 0.0 &&
         d.strain() >= steady_at_ + steady_cfg_.measure_strain;
}

template <class D>
void PressureCellObserverOf<D>::finish(const Dynamics& d, nlohmann::json& js, H5mdWriter* writer) {
  js[summary_key::steady] = steady();
  js[summary_key::steady_strain] =
      steady() ? nlohmann::json(steady_from_) : nlohmann::json(nullptr);
  js[summary_key::steady_detected_at] =
      steady() ? nlohmann::json(steady_at_) : nlohmann::json(nullptr);
  // Over every step where the packing holds the wall (free-fall steps are counted apart).
  js[summary_key::pressure_max_relative_error] = max_p_err_;
  js[summary_key::wall_free_fall_steps] = free_fall_steps_;
  if (!steady() || w_ <= 0.0) {
    js[summary_key::steady] = false;
    js[summary_key::note] =
        steady() ? "steady state detected at the last step: nothing measured after it; "
                   "run longer (run.strain)"
                 : "steady state not reached: H or mu still drift; run longer (run.strain)";
    js[summary_key::H] = d.height();
    js[summary_key::phi] = bulk_phi(d, exclusion_);
    return;
  }
  const double phi = phi_ / w_;
  js[summary_key::H] = h_ / w_;
  js[summary_key::phi] = phi;
  js[summary_key::phi_std] = std::sqrt(std::max(0.0, phi2_ / w_ - phi * phi));
  js[summary_key::mu] = 0.5 * (mu_top_ + mu_bottom_) / w_;
  js[summary_key::mu_top] = mu_top_ / w_;
  js[summary_key::mu_bottom] = mu_bottom_ / w_;
  js[summary_key::pressure_measured] = p_meas_ / w_;
  js[summary_key::measured_strain] = d.strain() - steady_at_;
  // The window's blocks span its frames, first to last: what `sheardiff analyse` sees too.
  const double last = window_.samples() == 0 ? d.strain() : window_.last_time();
  add_steady_errors(js, window_, steady_at_, last, error_block_);
  add_window_blocks(js, window_, steady_at_, last, error_block_);
  add_stationarity(
      js, pressure_cell_stationarity(steady_cfg_, window_, steady_at_, last, error_block_));
  (void)writer;
}

template <class D>
void PressureCellObserverOf<D>::serialize_window(Archive& a) {
  if (!a.loading() || a.layout() >= 7) return a.io(window_);
  // Layout 6 kept every frame's samples of the window (strain, H, phi, mu_top, mu_bottom, net
  // y drag, bulk load): binned as the run would have binned them.
  std::vector<double> strain, h, phi, mu_top, mu_bottom, drag, load;
  for (auto* v : {&strain, &h, &phi, &mu_top, &mu_bottom, &drag, &load}) a.io(*v);
  for (auto* v : {&h, &phi, &mu_top, &mu_bottom, &drag, &load})
    if (v->size() != strain.size())
      throw std::runtime_error("checkpoint: the pressure cell's window samples differ in length");
  window_ = cell_window(strain, h, phi, mu_top, mu_bottom, drag, load,
                        -std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity());
}

template class PressureCellObserverOf<Dim2>;
template class PressureCellObserverOf<Dim3>;

}  // namespace sheardiff
