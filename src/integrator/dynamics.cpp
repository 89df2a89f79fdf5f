#include "sheardiff/integrator/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sheardiff {

template <class D>
DynamicsOf<D>::DynamicsOf(Particles particles, Box box, ImposedFlow flow,
                          ForceBalance force_balance, NeighbourList neighbours, StepLimits limits,
                          std::optional<WallBodies> walls)
    : particles_(std::move(particles)),
      box_(box),
      flow_(flow),
      force_balance_(std::move(force_balance)),
      neighbours_(std::move(neighbours)),
      limits_(limits),
      walls_(std::move(walls)) {
  rebuild();
}

template <class D>
void DynamicsOf<D>::rebuild() {
  neighbours_.rebuild(particles_, box_);
  force_balance_.on_rebuild(particles_, neighbours_.pairs());
}

template <class D>
double DynamicsOf<D>::height() const {
  if (!walls_) return box_.ly;
  return mean_height(particles_, walls_->top) - mean_height(particles_, walls_->bottom);
}

template <class D>
void DynamicsOf<D>::begin_step() {
  // The rebuild waits until here so that pair terms stay those of the last solve until then
  // (observers read forces after the move).
  if (rebuild_due_) {
    rebuild();
    rebuild_due_ = false;
  }
  ForceBalance::update_contacts(particles_, box_, neighbours_.pairs());
  // A driven wall moves with the fluid at its height (the bottom wall is the flow's rest frame).
  if (walls_ && walls_->top_role != WallRole::Fixed) {
    Point top = Point::Zero();
    top.y() = mean_height(particles_, walls_->top);
    walls_->driven_vx = flow_.velocity(top).x();
  }
}

template <class D>
bool DynamicsOf<D>::solve(double dt_implicit, Velocities& v) {
  return force_balance_.solve(particles_, box_, flow_, neighbours_.pairs(), dt_implicit,
                              wall_bodies(), v);
}

template <class D>
bool DynamicsOf<D>::resolve_with_sticking(double dt_implicit,
                                          const std::vector<std::size_t>& switched, Velocities& v) {
  return force_balance_.resolve_with_sticking(particles_, box_, flow_, neighbours_.pairs(),
                                              switched, dt_implicit, wall_bodies(), v);
}

template <class D>
int DynamicsOf<D>::stick_reversed_sliding(const Velocities& v, double dt,
                                          std::vector<std::size_t>* switched) {
  return force_balance_.stick_reversed_sliding(particles_, neighbours_.pairs(), v.u, dt, switched);
}

const char* to_string(StepLimit l) {
  switch (l) {
    case StepLimit::Fixed:
      return "fixed";
    case StepLimit::Strain:
      return "strain";
    case StepLimit::Displacement:
      return "displacement";
    case StepLimit::Gap:
      return "gap";
    case StepLimit::Overlap:
      return "overlap";
    case StepLimit::Explicit:
      return "explicit_stability";
    case StepLimit::Growth:
      return "growth";
    case StepLimit::Count:
      break;
  }
  return "?";
}

template <class D>
double DynamicsOf<D>::fixed_step() const {
  const double rest = limits_.end_time - time_;
  return rest > 0.0 && rest < limits_.fixed_dt ? rest : limits_.fixed_dt;
}

template <class D>
double DynamicsOf<D>::landed(double dt) const {
  const double rate = flow_.clock_rate();
  if (limits_.fixed_dt > 0.0 || landing_ <= 0.0 || rate <= 0.0) return dt;
  const double to_go = landing_ / rate - time_;
  return to_go > 0.0 && dt >= to_go ? to_go : dt;
}

template <class D>
double DynamicsOf<D>::dt_limit(const Velocities& v, StepLimit* which) const {
  StepLimit why = StepLimit::Fixed;
  const auto take = [&](double cand, double& dt, StepLimit l) {
    if (cand < dt) dt = cand, why = l;
  };
  if (limits_.fixed_dt > 0.0) {
    if (which) *which = why;
    return fixed_step();
  }
  constexpr double kBig = std::numeric_limits<double>::infinity();
  const double clock_rate = flow_.clock_rate();
  double dt = clock_rate > 0.0 ? limits_.max_strain_step / clock_rate : kBig;
  why = StepLimit::Strain;
  double vmax = 0.0;
  for (std::size_t i = 0; i < particles_.n_mobile; ++i) {
    const typename D::Body na =
        v.u[i] - force_balance_.fluid_velocity(flow_, v, particles_.position[i]);
    vmax = std::max(vmax, na.template head<D::space>().squaredNorm());
  }
  vmax = std::sqrt(vmax);
  if (walls_) vmax = std::max(vmax, std::abs(v.wall_v));
  if (vmax > 0.0) take(limits_.max_displacement / vmax, dt, StepLimit::Displacement);

  const auto& pairs = neighbours_.pairs();
  const auto& terms = force_balance_.terms();
  const double delta = force_balance_.lubrication() ? force_balance_.lubrication()->delta : 0.0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& t = terms[k];
    if (!t.on) continue;
    const typename D::Body uj = v.u[pairs[k].j] + t.image_j;
    const double opening =
        t.g.n.dot(uj.template head<D::space>() - v.u[pairs[k].i].template head<D::space>());
    if (pairs[k].history.touching) {
      if (opening != 0.0)
        take(limits_.max_overlap_change / std::abs(opening), dt, StepLimit::Overlap);
    } else if (opening < 0.0) {
      const double gap = t.g.r - t.g.s;
      take(limits_.max_gap_fraction * (gap + 0.5 * delta * t.g.s) / -opening, dt, StepLimit::Gap);
      if (limits_.max_entry_overlap > 0.0)
        take((std::max(gap, 0.0) + limits_.max_entry_overlap) / -opening, dt, StepLimit::Gap);
    }
  }
  if (limits_.explicit_dt > 0.0) take(limits_.explicit_dt, dt, StepLimit::Explicit);
  if (which) *which = why;
  return dt;
}

template <class D>
void DynamicsOf<D>::advance(double dt, const Velocities& v, bool allow_rebuild) {
  // The pair laws' histories (contact springs) advance at the geometry of the start of the
  // step (recomputed: after a Heun corrector the pair terms hold the predicted geometry) ...
  auto& pairs = neighbours_.pairs();
  force_balance_.advance_histories(particles_, box_, flow_, pairs, v.u, dt);
  na_.resize(particles_.size());
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const Point step = v.u[i].template head<D::space>() * dt;
    if (particles_.motion[i] == Motion::FixedWall) {
      na_[i].setZero();
      continue;
    }
    na_[i] =
        step -
        force_balance_.fluid_velocity(flow_, v, particles_.position[i]).template head<D::space>() *
            dt;
    particles_.position[i] += step;
    particles_.unwrapped[i] += step;
    particles_.velocity[i] = v.u[i];
  }
  if (box_.lees_edwards) box_.le_offset += flow_.image_velocity_x(1, box_.ly) * dt;
  // ... and are capped at its end, where their forces are next evaluated.
  force_balance_.cap_histories(particles_, box_, pairs);
  time_ += dt;
  neighbours_.advance(na_, force_balance_.max_shear_rate(flow_, v) * dt);
  if (allow_rebuild && neighbours_.needs_rebuild()) rebuild_due_ = true;
}

template <class D>
void DynamicsOf<D>::serialize(Archive& a, bool layout5) {
  a.tag("dynamics");
  a.io(particles_.position);
  a.io(particles_.unwrapped);
  a.io(particles_.velocity);
  a.io(box_);
  a.io(time_);
  a.io(steps_);
  a.io(rebuild_due_);
  a.io(limit_counts_);
  // The driven wall's state, in the layout of earlier checkpoints (vx, load, free-fall cap).
  double wall_state[3] = {0.0, 0.0, 1.0};
  if (walls_) {
    wall_state[0] = walls_->driven_vx;
    wall_state[1] = walls_->load;
    wall_state[2] = walls_->free_fall_cap;
  }
  a.io(wall_state);
  if (a.loading() && walls_) walls_->driven_vx = wall_state[0];
  if (layout5) {
    a.tag("images");
    particles_.image.resize(particles_.size(), typename D::Images{});
    a.io(particles_.image);
  } else if (a.loading()) {
    estimate_images();
  }
  neighbours_.serialize(a);
  if (layout5) force_balance_.serialize_fluid_pattern(a);
  if (a.loading()) force_balance_.on_rebuild(particles_, neighbours_.pairs(), layout5);
}

template <class D>
void DynamicsOf<D>::estimate_images() {
  // Exact in y and without Lees-Edwards; in x under Lees-Edwards the nearest count, which is
  // what a checkpoint of an earlier layout (no counts) can give.
  Particles& p = particles_;
  p.image.assign(p.size(), typename D::Images{});
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double iy =
        box_.lees_edwards ? std::round((p.unwrapped[i].y() - p.position[i].y()) / box_.ly) : 0.0;
    const double ix =
        std::round((p.unwrapped[i].x() - p.position[i].x() - iy * box_.le_offset) / box_.lx);
    p.image[i][0] = static_cast<int>(ix);
    p.image[i][1] = static_cast<int>(iy);
    if constexpr (D::space == 3)
      p.image[i][2] =
          static_cast<int>(std::round((p.unwrapped[i].z() - p.position[i].z()) / box_.lz));
  }
}

template <class D>
typename DynamicsOf<D>::Saved DynamicsOf<D>::save() const {
  Saved s{particles_.position, particles_.unwrapped, particles_.image, {}, box_, time_};
  s.contacts.reserve(neighbours_.pairs().size());
  for (const auto& pr : neighbours_.pairs()) s.contacts.push_back(pr.history);
  return s;
}

template <class D>
void DynamicsOf<D>::restore(const Saved& s) {
  particles_.position = s.position;
  particles_.unwrapped = s.unwrapped;
  particles_.image = s.image;
  box_ = s.box;
  time_ = s.time;
  auto& pairs = neighbours_.pairs();
  for (std::size_t k = 0; k < pairs.size(); ++k) pairs[k].history = s.contacts[k];
  // The Verlet bookkeeping of the undone move stays counted: that only rebuilds earlier.
}

template class DynamicsOf<Dim2>;
template class DynamicsOf<Dim3>;

}  // namespace sheardiff
