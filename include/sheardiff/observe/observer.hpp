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
template <class D>
using MeasuredWindowOf = std::function<bool(const DynamicsOf<D>&)>;

// What an observer sees after a step.
template <class D>
struct StepViewOf {
  const DynamicsOf<D>& dynamics;
  const VelocitiesOf<D>& velocities;
  const StressSample& stress;
  double dt;
  // The step's solves (IntegratorOf::stages): pair sums over forces run over them.
  std::vector<StageOf<D>> stages;
};

// Reads the state after steps; never changes it. A run composes only the observers its scene
// and config ask for. Written for the run's dimension D (Dim2: discs, Dim3: spheres).
template <class D>
class ObserverOf {
 public:
  using Dynamics = DynamicsOf<D>;
  using StepView = StepViewOf<D>;

  virtual ~ObserverOf() = default;
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
template <class D>
using ObserverListOf = std::vector<std::unique_ptr<ObserverOf<D>>>;

// Stress and contact statistics of any scene, time-averaged after run.transient_strain.
template <class D>
class RheologyObserverOf final : public ObserverOf<D> {
 public:
  using typename ObserverOf<D>::Dynamics;
  using typename ObserverOf<D>::StepView;

  explicit RheologyObserverOf(double transient_strain) : transient_(transient_strain) {}
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

// The disc names (the 2D instantiation).
using MeasuredWindow = MeasuredWindowOf<Dim2>;
using StepView = StepViewOf<Dim2>;
using Observer = ObserverOf<Dim2>;
using ObserverList = ObserverListOf<Dim2>;
using RheologyObserver = RheologyObserverOf<Dim2>;

}  // namespace sheardiff
