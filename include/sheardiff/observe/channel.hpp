#pragma once
// What the channel scene measures (docs/channel.md, "Outputs"): profiles across the channel in
// bins of a/2 (areal fraction, particle and fluid velocity, the suspension temperature in both of
// the seed's definitions), the pressure gradient and the mean distance of the discs from the
// centreline, as a history of rows every channel.sample_interval; a detector of the steady state
// of the migration; and at the end the steady profiles and the seed's Table 1 columns.
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/observe/observer.hpp"

namespace sheardiff {

// The migration's history: one row per sample interval (the last one possibly still open).
struct ChannelHistory {
  static constexpr std::array<const char*, 5> profile_names = {"phi", "u_p", "u_f", "T_time",
                                                               "T_instant"};
  std::vector<double> y;     // bin centres over H, from the bottom wall row's surface
  std::vector<double> time;  // a / <u>, end of each interval
  std::vector<double> pressure_gradient_ratio, centre_distance /* d */, u_p_mean;
  // Per profile_names entry, rows x bins; NaN where a bin held no disc.
  std::array<std::vector<std::vector<double>>, 5> profiles;
};

// DIR/channel.h5: /channel_history/{y, time, pressure_gradient_ratio, centre_distance,
// u_p_mean} as float64 and the five profiles as compressed float32 tables (docs/channel.md).
void write_channel_history(const ChannelHistory& h, const std::filesystem::path& file);

class ChannelObserver final : public Observer {
 public:
  // history_file: where finish() writes the history (nothing written if empty).
  explicit ChannelObserver(const Config& cfg, std::filesystem::path history_file = {});
  std::vector<std::string> frame_names() const override;
  std::vector<std::string> frame_units() const override;
  void on_frame(const StepView& v, std::vector<double>& values) override;
  void on_step(const StepView& v) override;
  void finish(const Dynamics& d, nlohmann::json& summary, H5mdWriter* writer) override;
  void serialize(Archive& a) override;
  std::string progress() const override;

  // The time (a / <u>) from which the migration is steady; negative while it is not.
  double steady_time() const { return steady_time_; }
  // The history up to now.
  ChannelHistory history(const Dynamics& d) const;

 private:
  // Sums over one sample interval (weights dt): per bin the disc area, its x velocity, the
  // fluid velocity, and over the discs counted in the temperature (not captured by a wall) their
  // area, velocity, |u|^2 and |u - (the bin's instantaneous mean)|^2.
  struct Interval {
    double start = 0, end = 0, w = 0, g = 0, centre = 0, up = 0;
    std::vector<double> area, ux, uf, tw, tux, tuy, tu2, tinst;
    void reset(std::size_t bins, double at);
    void add(const Interval& o);
    void serialize(Archive& a);
  };
  // The interval's rows: phi, u_p / <u>, U_f / <u>, T (about the time mean), T (about the
  // instantaneous mean); T in <u>^2 (a/H)^2.
  std::vector<std::vector<double>> profiles(const Interval& s) const;
  // The closed intervals and the open one, ending now (a run's length need not be a whole
  // number of them).
  std::vector<Interval> intervals(const Dynamics& d) const;
  ChannelHistory history_of(const std::vector<Interval>& all) const;
  void close_interval(double now);
  void detect_steady();

  double phi_b_, u_mean_, a_ = 0.5, y_lo_, height_, bin_, interval_, window_, tolerance_;
  double g0_, lx_ = 1.0;
  std::filesystem::path history_file_;
  std::size_t bins_;
  double steady_time_ = -1.0;
  Interval now_;
  std::vector<Interval> closed_;  // the history, one per closed interval
};

}  // namespace sheardiff
