#include "sheardiff/integrator/integrators.hpp"

#include <algorithm>

namespace sheardiff {

namespace {
constexpr int kStickPasses = 4;  // re-solves per step for sliding contacts that stick
}  // namespace

template <class D>
bool ExplicitEulerOf<D>::step(DynamicsOf<D>& d) {
  d.begin_step();
  if (!d.solve(0.0, last_)) return false;
  ++solves_;
  StepLimit why;
  dt_ = d.landed(d.dt_limit(last_, &why));
  d.count_step_limit(why);
  d.advance(dt_, last_);
  d.finish_step();
  return true;
}

template <class D>
bool HeunOf<D>::step(Dynamics& d) {
  d.begin_step();
  if (!d.solve(0.0, predictor_)) return false;
  ++solves_;
  StepLimit why;
  dt_ = d.landed(d.dt_limit(predictor_, &why));
  d.count_step_limit(why);
  predictor_terms_ = d.force_balance().terms();
  const typename Dynamics::Saved start = d.save();
  d.advance(dt_, predictor_, /*allow_rebuild=*/false);
  const bool ok = d.solve(0.0, last_);
  ++solves_;
  corrector_ = last_;
  corrector_terms_ = d.force_balance().terms();
  d.restore(start);
  if (!ok) return false;
  for (std::size_t i = 0; i < last_.u.size(); ++i)
    last_.u[i] = 0.5 * (last_.u[i] + predictor_.u[i]);
  last_.wall_v = 0.5 * (last_.wall_v + predictor_.wall_v);
  // The wall load holds in the mean sample only if it held at both stages.
  last_.wall_free_fall = last_.wall_free_fall || predictor_.wall_free_fall;
  d.advance(dt_, last_);
  d.finish_step();
  return true;
}

template <class D>
bool ImplicitSpringsOf<D>::step(DynamicsOf<D>& d) {
  d.begin_step();
  const bool fixed = d.limits().fixed_dt > 0.0;
  double dt = fixed ? d.fixed_step() : next_dt_;
  if (dt <= 0.0) {
    // First step: the limits evaluated on the explicit-spring velocities.
    if (!d.solve(0.0, last_)) return false;
    ++solves_;
    dt = d.dt_limit(last_);
  }
  // The step the limits chose, before it is shortened to land on a frame: the next one grows
  // from it, so that landing costs one short step and no slow regrowth.
  double wanted = dt;
  if (!fixed) dt = d.landed(dt);
  StepLimit why = fixed ? StepLimit::Fixed : limit_of_next_;
  for (int attempt = 0;; ++attempt) {
    if (!d.solve(dt, last_)) return false;
    ++solves_;
    // Sliding contacts whose explicit Coulomb force reversed their slip stick instead and the
    // step is solved again with their tangential stiffness (a few passes: contacts only ever
    // go from sliding to sticking here). Which slips count as reversed is contact.stick_rule
    // (FrictionalContact::stick_after_slip; the rules differ only between spheres). Without
    // this, at steps where the cap force reverses the slip by more than the cap in one step,
    // such contacts chatter between +cap and -cap (docs/low_j.md).
    // The re-solve adds only the switched contacts' tangential stiffness, a low-rank change
    // solved on the same factor (a new factorisation doubled the cost of a step).
    for (int pass = 0; pass < kStickPasses && d.stick_reversed_sliding(last_, dt, &switched_) > 0;
         ++pass) {
      if (!d.resolve_with_sticking(dt, switched_, last_)) return false;
      ++solves_;
    }
    if (fixed) break;
    StepLimit now;
    const double allowed = d.dt_limit(last_, &now);
    if (dt <= overshoot_ * allowed || attempt == 3) {
      next_dt_ = std::min(growth_ * wanted, allowed);
      limit_of_next_ = growth_ * wanted < allowed ? StepLimit::Growth : now;
      break;
    }
    wanted = allowed;
    dt = d.landed(allowed);
    why = now;
    ++redos_;
  }
  d.count_step_limit(why);
  dt_ = dt;
  d.advance(dt_, last_);
  d.finish_step();
  return true;
}

template <class D>
std::unique_ptr<IntegratorOf<D>> make_integrator_of(IntegratorType type) {
  switch (type) {
    case IntegratorType::Euler:
      return std::make_unique<ExplicitEulerOf<D>>();
    case IntegratorType::Heun:
      return std::make_unique<HeunOf<D>>();
    case IntegratorType::Implicit:
      return std::make_unique<ImplicitSpringsOf<D>>();
  }
  return nullptr;
}

template class ExplicitEulerOf<Dim2>;
template class ExplicitEulerOf<Dim3>;
template class HeunOf<Dim2>;
template class HeunOf<Dim3>;
template class ImplicitSpringsOf<Dim2>;
template class ImplicitSpringsOf<Dim3>;
template std::unique_ptr<IntegratorOf<Dim2>> make_integrator_of<Dim2>(IntegratorType);
template std::unique_ptr<IntegratorOf<Dim3>> make_integrator_of<Dim3>(IntegratorType);

}  // namespace sheardiff
