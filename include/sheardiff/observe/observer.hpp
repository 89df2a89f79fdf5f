#pragma once
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sheardiff/integrator/dynamics.hpp"
#include "sheardiff/integrator/stress.hpp"

namespace sheardiff {

class H5mdWriter;

// Whether the run is in its measured window now (after the transient, or from a detected
// steady state): what observers that average only over it are given.
using MeasuredWindow = std::function<bool(const Dynamics&)>;

// What an observer sees after a step.
struct StepView {
  const Dynamics& dynamics;
  const Velocities& velocities;
  const StressSample& stress;
  double dt;
};

// Reads the state after steps; never changes it. A run composes only the observers its scene
// and config ask for.
class Observer {
 public:
  virtual ~Observer() = default;
  // Scalar observables written to every trajectory frame (names fixed for the run).
  virtual std::vector<std::string> frame_names() const { return {}; }
  // Their H5MD unit strings in the project's units (docs/trajectory.md), same order.
  virtual std::vector<std::string> frame_units() const {
    return std::vector<std::string>(frame_names().size(), "1");
  }
  // Called on frame steps; appends one value per frame_names() entry.
  virtual void on_frame(const StepView&, std::vector<double>& values) { (void)values; }
  // Called after every step (time averages).
  virtual void on_step(const StepView&) {}
  // Whether the run may stop now (e.g. measured long enough after steady state).
  virtual bool done(const Dynamics&) const { return false; }
  // The strain at which done() will turn true, once it is known (the progress line's end).
  virtual double planned_end_strain() const { return std::numeric_limits<double>::infinity(); }
  // A few words for the progress line (how far the run's slow process has come), or nothing.
  virtual std::string progress() const { return {}; }
  // Accumulated state, for checkpoints.
  virtual void serialize(Archive& a) { (void)a; }
  // Results into summary.json, tables into the trajectory (writer may be null).
  virtual void finish(const Dynamics&, nlohmann::json& summary, H5mdWriter* writer) {
    (void)summary;
    (void)writer;
  }
};

// A run's observers, in their update order.
using ObserverList = std::vector<std::unique_ptr<Observer>>;

// Stress and contact statistics of any scene, time-averaged after run.transient_strain.
class RheologyObserver final : public Observer {
 public:
  explicit RheologyObserver(double transient_strain) : transient_(transient_strain) {}
  std::vector<std::string> frame_names() const override;
  std::vector<std::string> frame_units() const override;
  void on_frame(const StepView& v, std::vector<double>& values) override;
  void on_step(const StepView& v) override;
  void finish(const Dynamics& d, nlohmann::json& summary, H5mdWriter* writer) override;
  void serialize(Archive& a) override {
    a.tag("rheology");
    for (double* x : {&weight_, &sxy_, &pressure_, &contacts_, &mean_overlap_, &max_overlap_})
      a.io(*x);
  }

 private:
  double transient_;
  double weight_ = 0, sxy_ = 0, pressure_ = 0, contacts_ = 0, mean_overlap_ = 0;
  double max_overlap_ = 0;
};

}  // namespace sheardiff
