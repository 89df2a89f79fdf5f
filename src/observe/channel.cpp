#include "sheardiff/observe/channel.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "sheardiff/interactions/fluid_layer.hpp"
#include "sheardiff/io/hdf5_tables.hpp"
#include "sheardiff/io/summary_keys.hpp"
#include "sheardiff/observe/profiles.hpp"

namespace sheardiff {

namespace {
constexpr double kCaptureGap =
    0.01;  // in a: the seed leaves discs this close to a wall disc out of T
}

ChannelObserver::ChannelObserver(const Config& cfg, std::filesystem::path history_file)
    : phi_b_(cfg.channel.phi),
      u_mean_(cfg.channel.mean_velocity),
      y_lo_(0.5),  // the bottom wall row's surface (scene/channel.cpp)
      height_(cfg.channel.h_over_a * 0.5),
      interval_(cfg.channel.sample_interval),
      window_(cfg.channel.steady_window),
      tolerance_(cfg.channel.steady_tolerance),
      history_file_(std::move(history_file)) {
  // Bins of (about) a/2 tiling the channel exactly, as the seed's figures.
  bins_ = static_cast<std::size_t>(std::max(1L, std::lround(height_ / (0.5 * a_))));
  bin_ = height_ / static_cast<double>(bins_);
  g0_ = 12.0 * u_mean_ / (height_ * height_);
  now_.reset(bins_, 0.0);
}

void ChannelObserver::Interval::reset(std::size_t bins, double at) {
  start = at;
  w = g = centre = up = 0.0;
  for (auto* v : {&area, &ux, &uf, &tw, &tux, &tuy, &tu2, &tinst}) v->assign(bins, 0.0);
}

void ChannelObserver::Interval::add(const Interval& o) {
  w += o.w, g += o.g, centre += o.centre, up += o.up;
  const std::vector<double>* theirs[] = {&o.area, &o.ux,  &o.uf,  &o.tw,
                                         &o.tux,  &o.tuy, &o.tu2, &o.tinst};
  std::vector<double>* mine[] = {&area, &ux, &uf, &tw, &tux, &tuy, &tu2, &tinst};
  for (int k = 0; k < 8; ++k)
    for (std::size_t b = 0; b < mine[k]->size(); ++b) (*mine[k])[b] += (*theirs[k])[b];
}

void ChannelObserver::Interval::serialize(Archive& a) {
  a.io(start), a.io(end), a.io(w), a.io(g), a.io(centre), a.io(up);
  for (auto* v : {&area, &ux, &uf, &tw, &tux, &tuy, &tu2, &tinst}) a.io(*v);
}

std::vector<std::string> ChannelObserver::frame_names() const {
  return {"pressure_gradient_ratio", "centre_distance"};
}
std::vector<std::string> ChannelObserver::frame_units() const {
  return {"1", "d"};
}

void ChannelObserver::on_frame(const StepView& v, std::vector<double>& values) {
  const Particles& p = v.dynamics.particles();
  const double yc = y_lo_ + 0.5 * height_;
  double c = 0.0;
  for (std::size_t i = 0; i < p.n_mobile; ++i) c += std::abs(p.position[i].y() - yc);
  const double g = v.dynamics.force_balance().fluid() ? v.velocities.pressure_gradient : g0_;
  values.push_back(g / g0_);
  values.push_back(p.n_mobile ? c / static_cast<double>(p.n_mobile) : 0.0);
}

void ChannelObserver::on_step(const StepView& v) {
  const Dynamics& d = v.dynamics;
  const Particles& p = d.particles();
  const auto& u = v.velocities.u;
  const double w = v.dt;
  lx_ = d.box().lx;
  const auto nb = static_cast<long>(bins_);
  const double yc = y_lo_ + 0.5 * height_;
  // Discs captured by a wall (gap below kCaptureGap a to a wall disc) are left out of T. Such a
  // pair is well inside the interaction range, so the neighbour list holds it.
  std::vector<char> in_t(p.n_mobile, 1);
  for (const Pair& pr : d.neighbours().pairs()) {
    if (p.motion[pr.j] == Motion::Mobile) continue;
    const double gap = pair_separation(p, d.box(), pr).norm() - p.radius[pr.i] - p.radius[pr.j];
    if (gap < kCaptureGap * a_) in_t[static_cast<std::size_t>(pr.i)] = 0;
  }
  std::vector<double> ia(bins_, 0.0), iux(bins_, 0.0), iuy(bins_, 0.0);
  double centre = 0.0, up = 0.0;
  // Each disc's area in each bin it covers; its velocity weighted by that area.
  const auto each_share = [&](auto&& f) {
    for (std::size_t i = 0; i < p.n_mobile; ++i) {
      const double y = p.position[i].y() - y_lo_, a = p.radius[i];
      const long lo = std::max(0L, static_cast<long>(std::floor((y - a) / bin_)));
      const long hi = std::min(nb - 1, static_cast<long>(std::floor((y + a) / bin_)));
      for (long b = lo; b <= hi; ++b) {
        const double s = disc_area_between(y, a, b * bin_, (b + 1) * bin_);
        if (s > 0.0) f(i, static_cast<std::size_t>(b), s);
      }
    }
  };
  each_share([&](std::size_t i, std::size_t b, double s) {
    now_.area[b] += w * s;
    now_.ux[b] += w * s * u[i].x();
    if (!in_t[i]) return;
    ia[b] += s, iux[b] += s * u[i].x(), iuy[b] += s * u[i].y();
    now_.tw[b] += w * s;
    now_.tux[b] += w * s * u[i].x();
    now_.tuy[b] += w * s * u[i].y();
    now_.tu2[b] += w * s * u[i].head<2>().squaredNorm();
  });
  each_share([&](std::size_t i, std::size_t b, double s) {
    if (!in_t[i] || ia[b] <= 0.0) return;
    const Vec2 mean(iux[b] / ia[b], iuy[b] / ia[b]);
    now_.tinst[b] += w * s * (u[i].head<2>() - mean).squaredNorm();
  });
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    centre += std::abs(p.position[i].y() - yc);
    up += u[i].x();
  }
  const double n = std::max<double>(1.0, static_cast<double>(p.n_mobile));
  for (std::size_t b = 0; b < bins_; ++b) {
    const Vec2 x(0.0, y_lo_ + (static_cast<double>(b) + 0.5) * bin_);
    now_.uf[b] += w * d.force_balance().fluid_velocity(d.flow(), v.velocities, x).x();
  }
  const double g = d.force_balance().fluid() ? v.velocities.pressure_gradient : g0_;
  now_.w += w;
  now_.g += w * g / g0_;
  now_.centre += w * centre / n;
  now_.up += w * up / n;
  const double t = d.strain();
  if (t - now_.start >= interval_ * (1.0 - 1e-9)) close_interval(t);
}

void ChannelObserver::close_interval(double now) {
  now_.end = now;
  closed_.push_back(now_);
  now_.reset(bins_, now);
  detect_steady();
}

void ChannelObserver::detect_steady() {
  if (steady_time_ >= 0.0 || closed_.empty()) return;
  const double end = closed_.back().end;
  if (end < window_) return;
  // Mean centreline distance over the two halves of the last window.
  double w1 = 0, c1 = 0, w2 = 0, c2 = 0;
  const double mid = end - 0.5 * window_;
  for (const Interval& s : closed_) {
    if (s.start < end - window_ - 1e-9) continue;
    (s.start < mid - 1e-9 ? w1 : w2) += s.w;
    (s.start < mid - 1e-9 ? c1 : c2) += s.centre;
  }
  if (w1 <= 0.0 || w2 <= 0.0) return;
  const double m1 = c1 / w1, m2 = c2 / w2;
  if (std::abs(m2 - m1) <= tolerance_ * m2) steady_time_ = mid;
}

std::string ChannelObserver::progress() const {
  if (closed_.empty()) return {};
  // The migration as it goes: the last sample interval's centre distance and pressure gradient.
  const Interval& s = closed_.back();
  if (s.w <= 0.0) return {};
  const std::string steady =
      steady_time_ >= 0.0 ? fmt::format("steady from {:.4g}", steady_time_) : "not yet steady";
  return fmt::format("centre distance {:.3f} d  G/G0 {:.3f}  {}", s.centre / s.w, s.g / s.w,
                     steady);
}

std::vector<std::vector<double>> ChannelObserver::profiles(const Interval& s) const {
  std::vector<std::vector<double>> out(5, std::vector<double>(bins_, 0.0));
  const double lx_bin = bin_ * lx_;
  const double tscale = u_mean_ * u_mean_ * (a_ / height_) * (a_ / height_);
  for (std::size_t b = 0; b < bins_; ++b) {
    out[0][b] = s.w > 0 ? s.area[b] / (s.w * lx_bin) : 0.0;
    out[1][b] = s.area[b] > 0 ? s.ux[b] / s.area[b] / u_mean_ : NAN;
    out[2][b] = s.w > 0 ? s.uf[b] / s.w / u_mean_ : NAN;
    if (s.tw[b] > 0) {
      const double mx = s.tux[b] / s.tw[b], my = s.tuy[b] / s.tw[b];
      out[3][b] = (s.tu2[b] / s.tw[b] - mx * mx - my * my) / tscale;
      out[4][b] = s.tinst[b] / s.tw[b] / tscale;
    } else {
      out[3][b] = out[4][b] = NAN;
    }
  }
  return out;
}

void ChannelObserver::serialize(Archive& a) {
  a.tag("channel");
  a.io(steady_time_), a.io(lx_);
  now_.serialize(a);
  std::uint64_t n = closed_.size();
  a.io(n);
  if (a.loading()) closed_.resize(n);
  for (Interval& s : closed_) s.serialize(a);
}

std::vector<ChannelObserver::Interval> ChannelObserver::intervals(const Dynamics& d) const {
  std::vector<Interval> all = closed_;
  if (now_.w > 0.0) {
    all.push_back(now_);
    all.back().end = d.strain();
  }
  return all;
}

ChannelHistory ChannelObserver::history(const Dynamics& d) const {
  return history_of(intervals(d));
}

ChannelHistory ChannelObserver::history_of(const std::vector<Interval>& all) const {
  ChannelHistory h;
  for (std::size_t b = 0; b < bins_; ++b)
    h.y.push_back((static_cast<double>(b) + 0.5) * bin_ / height_);
  for (const Interval& s : all) {
    if (s.w <= 0) continue;
    h.time.push_back(s.end);
    h.pressure_gradient_ratio.push_back(s.g / s.w);
    h.centre_distance.push_back(s.centre / s.w);
    h.u_p_mean.push_back(s.up / s.w / u_mean_);
    auto pr = profiles(s);
    for (int k = 0; k < 5; ++k) h.profiles[k].push_back(std::move(pr[k]));
  }
  return h;
}

void write_channel_history(const ChannelHistory& h, const std::filesystem::path& file) {
  // Written under a temporary name and renamed, so a complete-looking file is complete.
  const auto tmp = file.string() + ".tmp";
  {
    H5Id f{H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose};
    if (f.id < 0) throw std::runtime_error("cannot create " + tmp);
    // Units and descriptions as docs/outputs.md gives them.
    write_vector(f.id, "/channel_history/y", h.y, "H", "bin centres across the channel, y/H");
    write_vector(f.id, "/channel_history/time", h.time, "a/<u>", "end of each sample interval");
    write_vector(f.id, "/channel_history/pressure_gradient_ratio", h.pressure_gradient_ratio, "1",
                 "pressure gradient over Poiseuille's G0 = 12 eta <u> / H^2, interval mean");
    write_vector(f.id, "/channel_history/centre_distance", h.centre_distance, "d",
                 "mean distance of the mobile discs from the centreline, interval mean");
    write_vector(f.id, "/channel_history/u_p_mean", h.u_p_mean, "<u>",
                 "mean x velocity of the mobile discs, interval mean");
    // float32: one bin of one interval averages a few tens of disc samples, a statistical
    // error of several per cent, far above float32's 1e-7; as text the profiles made a long
    // run's summary megabytes.
    // In the order of ChannelHistory::profile_names, as docs/outputs.md gives them.
    const std::array<const char*, 5> profile_units = {"1", "<u>", "<u>", "<u>^2 (a/H)^2",
                                                      "<u>^2 (a/H)^2"};
    for (int k = 0; k < 5; ++k)
      write_compressed_table(f.id, std::string("/channel_history/") + h.profile_names[k],
                             h.profiles[k], h.y.size(), profile_units[k],
                             "profile across the channel, one row per sample interval, one "
                             "column per bin of y (NaN: no disc in the bin)");
  }
  std::filesystem::rename(tmp, file);
}

void ChannelObserver::finish(const Dynamics& d, nlohmann::json& js, H5mdWriter* writer) {
  (void)writer;
  // NaN (an empty bin) is written as null.
  const auto list = [](const std::vector<double>& v) {
    nlohmann::json j = nlohmann::json::array();
    for (double x : v) j.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json());
    return j;
  };
  const std::vector<Interval> all = intervals(d);
  const ChannelHistory h = history_of(all);
  js[summary_key::channel_y] = h.y;
  js[summary_key::channel_H_over_a] = height_ / a_;
  js[summary_key::channel_phi_bulk] = phi_b_;
  js[summary_key::channel_mean_velocity] = u_mean_;
  js[summary_key::channel_coupling] = d.force_balance().fluid() ? "two_way" : "one_way";
  js["channel_pressure_gradient_poiseuille"] = g0_;
  if (!history_file_.empty()) {
    write_channel_history(h, history_file_);
    js[summary_key::channel_history_file] = history_file_.filename().string();
  }

  // The steady state: from the detected time, else the second half of the run (flagged).
  const bool steady = steady_time_ >= 0.0;
  js[summary_key::channel_steady] = steady;
  js[summary_key::channel_steady_time] = steady ? nlohmann::json(steady_time_) : nlohmann::json();
  double from = steady ? steady_time_ : 0.0;
  if (!steady && !all.empty()) from = 0.5 * all.back().end;
  Interval sum;
  sum.reset(bins_, from);
  for (const Interval& s : all)
    if (s.start >= from - 1e-9) sum.add(s);
  if (sum.w <= 0.0) return;
  js[summary_key::channel_average_from] = from;
  const auto pr = profiles(sum);
  for (int k = 0; k < 5; ++k)
    js[std::string("channel_") + ChannelHistory::profile_names[k]] = list(pr[k]);
  // The seed's Table 1 columns: centre values (the two bins at the centreline), the width
  // average of the particle velocity profile (bins holding discs), the particle flux
  // mean(phi u_p) / phi_b and the pressure gradient over Poiseuille's.
  const std::size_t c_lo = (bins_ - 1) / 2, c_hi = bins_ / 2;
  const auto centre = [&](const std::vector<double>& v) { return 0.5 * (v[c_lo] + v[c_hi]); };
  double up_sum = 0, up_n = 0, q = 0;
  for (std::size_t b = 0; b < bins_; ++b) {
    if (std::isfinite(pr[1][b])) up_sum += pr[1][b], up_n += 1, q += pr[0][b] * pr[1][b];
  }
  js[summary_key::channel_u_c] = centre(pr[1]);
  js[summary_key::channel_phi_c] = centre(pr[0]);
  js[summary_key::channel_u_p_mean] = up_n > 0 ? nlohmann::json(up_sum / up_n) : nlohmann::json();
  js[summary_key::channel_Q_p] = q / static_cast<double>(bins_) / phi_b_;
  js[summary_key::channel_dp_ratio] = sum.g / sum.w;
  js[summary_key::channel_centre_distance] = sum.centre / sum.w;
  js[summary_key::channel_mean_particle_velocity] = sum.up / sum.w / u_mean_;
}

}  // namespace sheardiff
