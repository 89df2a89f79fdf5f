#include "sheardiff/solver/force_balance.hpp"

#include <stdexcept>

namespace sheardiff {

namespace {
PairGeometry pair_geometry(const Particles& p, const Box& box, const Pair& pr) {
  return PairGeometry::make(pair_separation(p, box, pr), p.radius[pr.i], p.radius[pr.j]);
}
}  // namespace

ForceBalance::ForceBalance(PairLaws laws, int dof, bool implicit_springs,
                           const std::string& cholesky)
    : laws_(std::move(laws)),
      system_(dof, cholesky),
      diagonal_only_(!laws_.resistive() && !implicit_springs) {}

void ForceBalance::on_rebuild(const Particles& p, const std::vector<Pair>& pairs, bool restored) {
  terms_.assign(pairs.size(), PairTerm{});
  if (fluid_) {
    if (!restored || pattern_y_.size() != p.n_mobile) {
      pattern_y_.resize(p.n_mobile);
      for (std::size_t i = 0; i < p.n_mobile; ++i) pattern_y_[i] = p.position[i].y();
    }
    const int base = system_.dof() * static_cast<int>(p.n_mobile);
    system_.set_pattern(p.n_mobile, pairs, p, false, fluid_->unknowns(),
                        fluid_->pattern(pattern_y_, system_.dof(), base));
    fluid_load_ = fluid_->load(system_.unknowns(), base);
  } else {
    system_.set_pattern(p.n_mobile, pairs, p, diagonal_only_);
  }
}

void ForceBalance::update_contacts(const Particles& p, const Box& box, std::vector<Pair>& pairs) {
  for (Pair& pr : pairs) {
    const double r = pair_separation(p, box, pr).norm();
    const bool touching = r <= p.radius[pr.i] + p.radius[pr.j];
    if (touching != pr.history.touching) pr.history = PairHistory{touching, {}};
  }
}

void ForceBalance::advance_histories(const Particles& p, const Box& box, const ImposedFlow& flow,
                                     std::vector<Pair>& pairs, const std::vector<Vec3>& u,
                                     double dt) const {
  if (!laws_.keeps_history()) return;
  for (Pair& pr : pairs) {
    if (!pr.history.touching) continue;
    Vec6 up;
    up << u[pr.i], u[pr.j];
    if (p.motion[pr.j] == Motion::Mobile) up[3] += flow.image_velocity_x(pr.ky, box.ly);
    laws_.advance(pr.history, pair_geometry(p, box, pr), up, dt);
  }
}

void ForceBalance::cap_histories(const Particles& p, const Box& box,
                                 std::vector<Pair>& pairs) const {
  if (!laws_.keeps_history()) return;
  for (Pair& pr : pairs)
    if (pr.history.touching) laws_.cap(pr.history, pair_geometry(p, box, pr));
}

int ForceBalance::stick_reversed_sliding(const Particles& p, std::vector<Pair>& pairs,
                                         const std::vector<Vec3>& u,
                                         std::vector<std::size_t>* switched) const {
  (void)p;
  if (switched) switched->clear();
  int changed = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    PairHistory& h = pairs[k].history;
    if (!h.touching || !h.contact.sliding) continue;
    const PairTerm& t = terms_[k];
    Vec6 up;
    up << u[pairs[k].i], u[pairs[k].j] + t.image_j;
    if (FrictionalContact::stick_if_unloading(h.contact, t.g, up)) {
      ++changed;
      if (switched) switched->push_back(k);
    }
  }
  return changed;
}

template <bool kWalls>
void ForceBalance::assemble_pairs(const Particles& p, const Box& box, const ImposedFlow& flow,
                                  const std::vector<Pair>& pairs, double dt_implicit,
                                  const WallBodies* walls) {
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const Pair& pr = pairs[k];
    PairTerm& term = terms_[k];
    term.g = PairGeometry::make(pair_separation(p, box, pr), p.radius[pr.i], p.radius[pr.j]);
    term.on = laws_.add_blocks(term.g, pr.history, dt_implicit, term.m, term.f, term.sliding);
    if (!term.on) continue;
    term.image_j = Vec3::Zero();
    Vec3 known = Vec3::Zero();
    if constexpr (kWalls) {
      const Motion mj = p.motion[pr.j];
      if (mj == Motion::Mobile)
        known.x() = term.image_j.x() = flow.image_velocity_x(pr.ky, box.ly);
      else if (mj == Motion::FloatingWall || mj == Motion::DrivenWall)
        known.x() = walls->driven_vx;
      system_.add_pair(k, pr, term.m, term.f, known, mj == Motion::Mobile,
                       mj == Motion::FloatingWall);
    } else {
      known.x() = term.image_j.x() = flow.image_velocity_x(pr.ky, box.ly);
      system_.add_pair(k, pr, term.m, term.f, known, true, false);
    }
  }
}

bool ForceBalance::solve(const Particles& p, const Box& box, const ImposedFlow& flow,
                         const std::vector<Pair>& pairs, double dt_implicit,
                         const WallBodies* walls, Velocities& out) {
  assemble(p, box, flow, pairs, dt_implicit, walls);
  return solve_assembled(p, flow, walls, out);
}

bool ForceBalance::resolve_with_sticking(const Particles& p, const Box& box,
                                         const ImposedFlow& flow, const std::vector<Pair>& pairs,
                                         const std::vector<std::size_t>& switched,
                                         double dt_implicit, const WallBodies* walls,
                                         Velocities& out) {
  // A fresh assembly reads the contacts' new state: taken when a contact with the floating wall
  // switched (its column is not a low-rank term), or when the update would cost more
  // back-substitutions than a factorisation (many switched contacts at large N).
  const bool over_budget = !system_.low_rank_pays(switched.size());
  bool wall = false;
  for (std::size_t k : switched) wall = wall || p.motion[pairs[k].j] == Motion::FloatingWall;
  sticking_.switched += static_cast<long>(switched.size());
  if (over_budget || wall) {
    ++(over_budget ? sticking_.refactorised_budget : sticking_.refactorised_wall);
    return solve(p, box, flow, pairs, dt_implicit, walls, out);
  }
  ++sticking_.low_rank;
  const int d = system_.dof();
  VecX w, dg;
  for (std::size_t k : switched) {
    const Pair& pr = pairs[k];
    PairTerm& term = terms_[k];
    const double kt = dt_implicit * contact().kt_of(term.g);
    const Vec6 w6 = FrictionalContact::slip_mode(term.g);
    // The pair term as a new assembly would make it (stresses read it after the step).
    term.m += kt * w6 * w6.transpose();
    term.sliding = false;
    const bool j_mobile = p.motion[pr.j] == Motion::Mobile;
    // Known velocity of j's side: the Lees-Edwards image's, a driven wall's, or zero for a
    // fixed wall.
    const double known_x = j_mobile                               ? term.image_j.x()
                           : p.motion[pr.j] == Motion::DrivenWall ? walls->driven_vx
                                                                  : 0.0;
    w.setZero(static_cast<Eigen::Index>(system_.unknowns()));
    dg.setZero(w.size());
    const double wj_known = w6[3] * known_x;
    for (int r = 0; r < d; ++r) {
      w[d * pr.i + r] = w6[r];
      dg[d * pr.i + r] = -kt * w6[r] * wj_known;
      if (j_mobile) {
        w[d * pr.j + r] = w6[3 + r];
        dg[d * pr.j + r] = -kt * w6[3 + r] * wj_known;
      }
    }
    system_.add_low_rank(w, kt, dg);
  }
  return solve_assembled(p, flow, walls, out);
}

void ForceBalance::assemble(const Particles& p, const Box& box, const ImposedFlow& flow,
                            const std::vector<Pair>& pairs, double dt_implicit,
                            const WallBodies* walls) {
  if (terms_.size() != pairs.size()) throw std::logic_error("ForceBalance: stale pair list");
  if (dt_implicit > 0.0 && diagonal_only_)
    throw std::logic_error("ForceBalance: implicit springs need the coupled pattern");
  system_.clear();
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    const Vec3 drag = StokesDrag::resistance(p.radius[i]);
    Vec3 force = drag.cwiseProduct(flow.velocity(p.position[i]));
    if (!p.external.empty()) force += p.external[i];
    system_.add_self(static_cast<int>(i), drag, force);
  }
  if (fluid_)
    fluid_->assemble(p, flow, system_.dof(), static_cast<int>(system_.particle_unknowns()),
                     system_);
  // Scenes without walls get a loop with no wall branch at all.
  if (walls)
    assemble_pairs<true>(p, box, flow, pairs, dt_implicit, walls);
  else
    assemble_pairs<false>(p, box, flow, pairs, dt_implicit, walls);
}

bool ForceBalance::solve_assembled(const Particles& p, const ImposedFlow& flow,
                                   const WallBodies* walls, Velocities& out) {
  double v = 0.0, g = 0.0;
  bool capped = false;
  const bool ok =
      fluid_ ? system_.solve_with_multiplier(u_, fluid_load_, g)
      : walls && walls->floating()
          ? system_.solve_with_floating_wall(u_, walls->load, walls->free_fall_cap, v, capped)
          : system_.solve(u_);
  out.wall_free_fall = capped;
  if (!ok) return false;
  if (check_residual_) residual_ = system_.residual(u_, v);

  const int d = system_.dof();
  out.u.resize(p.size());
  out.wall_v = v;
  if (fluid_) {
    const auto base = static_cast<Eigen::Index>(system_.particle_unknowns());
    out.fluid.assign(u_.data() + base, u_.data() + u_.size());
    out.pressure_gradient = g;  // the multiplier is G itself: the reference's G0 is in g_
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    switch (p.motion[i]) {
      case Motion::Mobile:
        if (d == 3) {
          out.u[i] = Vec3(u_[d * i], u_[d * i + 1], u_[d * i + 2]);
        } else {
          // Without rotational unknowns only drag (and an external torque) acts on omega.
          double w = fluid_velocity(flow, out, p.position[i]).z();
          if (!p.external.empty()) w += p.external[i].z() / StokesDrag::resistance(p.radius[i]).z();
          out.u[i] = Vec3(u_[d * i], u_[d * i + 1], w);
        }
        break;
      case Motion::FixedWall:
        out.u[i].setZero();
        break;
      case Motion::FloatingWall:
        out.u[i] = walls ? Vec3(walls->driven_vx, v, 0.0) : Vec3::Zero();
        break;
      case Motion::DrivenWall:
        out.u[i] = walls ? Vec3(walls->driven_vx, 0.0, 0.0) : Vec3::Zero();
        break;
    }
  }
  return true;
}

}  // namespace sheardiff
