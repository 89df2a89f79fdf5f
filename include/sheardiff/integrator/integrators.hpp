#pragma once
#include <memory>

#include "sheardiff/config.hpp"
#include "sheardiff/integrator/dynamics.hpp"
#include "sheardiff/integrator/stress.hpp"

namespace sheardiff {

// A time-stepping policy over Dynamics (docs/model.md section 7), for discs (D = Dim2) or
// spheres (Dim3).
template <class D>
class IntegratorOf {
 public:
  using Dynamics = DynamicsOf<D>;
  using Velocities = VelocitiesOf<D>;

  virtual ~IntegratorOf() = default;
  // Advance one step. Returns false if a linear solve failed (state is then unchanged).
  virtual bool step(Dynamics& d) = 0;
  // The velocities at the configuration as it is, springs explicit, nothing moved: the state
  // of the frame at step 0. The next step solves again from the same configuration, so a run
  // steps as it would without this call. false if the solve failed.
  bool solve_at_rest(Dynamics& d) {
    d.begin_step();
    return d.solve(0.0, last_);
  }
  // Velocities of the last completed step (the ones the particles moved with), or those of
  // solve_at_rest before the first step.
  const Velocities& velocities() const { return last_; }
  double last_dt() const { return dt_; }
  long solves() const { return solves_; }
  // Stresses and wall forces of the last step, consistent with the velocities it moved with.
  virtual StressSample sample(const Dynamics& d, double lz) const {
    return measure_stress(d, last_, lz);
  }
  // The last step's solves with their shares of its motion (what observers sum pair forces over).
  virtual std::vector<StageOf<D>> stages(const Dynamics& d) const {
    return {{&d.force_balance().terms(), &last_, 1.0}};
  }
  // Whether the springs sit inside the matrix (the force balance must keep the full pattern).
  virtual bool implicit_springs() const { return false; }
  // Step-size memory and counters, for checkpoints.
  virtual void serialize(Archive& a) {
    a.tag("integrator");
    a.io(dt_);
    a.io(solves_);
    a.io(last_.u);
    a.io(last_.wall_v);
    a.io(last_.wall_free_fall);
  }

 protected:
  Velocities last_;
  double dt_ = 0.0;
  long solves_ = 0;
};

// Springs explicit, one solve per step.
template <class D>
class ExplicitEulerOf final : public IntegratorOf<D> {
 public:
  bool step(DynamicsOf<D>& d) override;

 private:
  using IntegratorOf<D>::last_, IntegratorOf<D>::dt_, IntegratorOf<D>::solves_;
};

// Springs explicit, predictor-corrector (two solves per step, second order).
template <class D>
class HeunOf final : public IntegratorOf<D> {
 public:
  using Dynamics = DynamicsOf<D>;
  bool step(Dynamics& d) override;
  // The particles moved with the mean of the two stages' velocities, so the stress is the mean
  // of the two stages' samples, each at its own geometry: the wall then carries exactly P Lx lz
  // as it does at each stage (one stage's terms with the mean velocities balance nothing).
  StressSample sample(const Dynamics& d, double lz) const override {
    return average(measure_stress(d, predictor_terms_, predictor_, lz),
                   measure_stress(d, corrector_terms_, corrector_, lz));
  }
  std::vector<StageOf<D>> stages(const Dynamics& d) const override {
    if (predictor_terms_.empty()) return IntegratorOf<D>::stages(d);  // at rest: one solve
    return {{&predictor_terms_, &predictor_, 0.5}, {&corrector_terms_, &corrector_, 0.5}};
  }

 private:
  using IntegratorOf<D>::last_, IntegratorOf<D>::dt_, IntegratorOf<D>::solves_;
  VelocitiesOf<D> predictor_, corrector_;
  std::vector<PairTermOf<D>> predictor_terms_, corrector_terms_;
};

// Linearly implicit springs: (A + dt K) U = g, stable for any dt; dt chosen by accuracy from
// the previous velocities, and the step is redone with a smaller dt if the solved velocities
// overshoot the limits by more than `overshoot`.
template <class D>
class ImplicitSpringsOf final : public IntegratorOf<D> {
 public:
  explicit ImplicitSpringsOf(double growth = 1.25, double overshoot = 1.5)
      : growth_(growth), overshoot_(overshoot) {}
  bool step(DynamicsOf<D>& d) override;
  bool implicit_springs() const override { return true; }
  long redos() const { return redos_; }
  void serialize(Archive& a) override {
    IntegratorOf<D>::serialize(a);
    a.io(next_dt_);
    a.io(limit_of_next_);
    a.io(redos_);
  }

 private:
  using IntegratorOf<D>::last_, IntegratorOf<D>::dt_, IntegratorOf<D>::solves_;
  double growth_, overshoot_;
  double next_dt_ = 0.0;
  StepLimit limit_of_next_ = StepLimit::Displacement;
  long redos_ = 0;
  std::vector<std::size_t> switched_;  // scratch: contacts switched to sticking in a pass
};

using Integrator = IntegratorOf<Dim2>;
using ExplicitEuler = ExplicitEulerOf<Dim2>;
using Heun = HeunOf<Dim2>;
using ImplicitSprings = ImplicitSpringsOf<Dim2>;

template <class D>
std::unique_ptr<IntegratorOf<D>> make_integrator_of(IntegratorType type);
inline std::unique_ptr<Integrator> make_integrator(IntegratorType type) {
  return make_integrator_of<Dim2>(type);
}

}  // namespace sheardiff
