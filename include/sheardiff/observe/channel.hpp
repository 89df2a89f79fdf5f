#pragma once
// What the channel scene measures (docs/channel.md, "Outputs"): profiles across the channel in
// bins of a/2 (areal fraction, particle and fluid velocity, the suspension temperature in both of
// the seed's definitions), the pressure gradient and the mean distance of the discs from the
// centreline, as a history of rows every channel.sample_interval; a detector of the steady state
// of the migration; and at the end the steady profiles and the seed's Table 1 columns.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sheardiff/config.hpp"
#include "sheardiff/observe/observer.hpp"

namespace sheardiff {

class ChannelObserver final : public Observer {
 public:
  explicit ChannelObserver(const Config& cfg);
  std::vector<std::string> frame_names() const override;
  std::vector<std::string> frame_units() const override;
  void on_frame(const StepView& v, std::vector<double>& values) override;
  void on_step(const StepView& v) override;
  void finish(const Dynamics& d, nlohmann::json& summary, H5mdWriter* writer) override;
  void serialize(Archive& a) override;
  std::string progress() const override;

  // The time (a / <u>) from which the migration is steady; negative while it is not.
  double steady_time() const { return steady_time_; }

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
  void close_interval(double now);
  void detect_steady();

  double phi_b_, u_mean_, a_ = 0.5, y_lo_, height_, bin_, interval_, window_, tolerance_;
  double g0_, lx_ = 1.0;
  std::size_t bins_;
  double steady_time_ = -1.0;
  Interval now_;
  std::vector<Interval> closed_;  // the history, one per closed interval
};

}  // namespace sheardiff
