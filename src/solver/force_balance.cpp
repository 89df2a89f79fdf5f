#include "sheardiff/solver/force_balance.hpp"

#include <stdexcept>

namespace sheardiff {

namespace {
template <class D>
PairGeometryOf<D> pair_geometry(const ParticlesOf<D>& p, const BoxOf<D>& box, const PairOf<D>& pr) {
  return PairGeometryOf<D>::make(pair_separation(p, box, pr), p.radius[pr.i], p.radius[pr.j]);
}
// A pair's generalised velocity from its particles'.
template <class D>
typename D::PairVector pair_velocity(const typename D::Body& ui, const typename D::Body& uj) {
  typename D::PairVector u;
  u << ui, uj;
  return u;
}
}  // namespace

template <class D>
ForceBalanceOf<D>::ForceBalanceOf(PairLaws laws, int dof, bool implicit_springs,
                                  const std::string& cholesky)
    : laws_(std::move(laws)),
      system_(dof, cholesky, D::space),
      diagonal_only_(!laws_.resistive() && !implicit_springs) {}

template <class D>
void ForceBalanceOf<D>::on_rebuild(const Particles& p, const std::vector<Pair>& pairs,
                                   bool restored) {
  terms_.assign(pairs.size(), PairTerm{});
  if constexpr (D::space == 3) {
    system_.set_pattern(p.n_mobile, pairs, p, diagonal_only_);
    (void)restored;
  } else if (fluid_) {
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

template <class D>
void ForceBalanceOf<D>::update_contacts(const Particles& p, const Box& box,
                                        std::vector<Pair>& pairs) {
  for (Pair& pr : pairs) {
    const double r = pair_separation(p, box, pr).norm();
    const bool touching = r <= p.radius[pr.i] + p.radius[pr.j];
    if (touching != pr.history.touching) pr.history = PairHistoryOf<D>{touching, {}};
  }
}

template <class D>
void ForceBalanceOf<D>::advance_histories(const Particles& p, const Box& box,
                                          const ImposedFlow& flow, std::vector<Pair>& pairs,
                                          const std::vector<Body>& u, double dt) const {
  if (!laws_.keeps_history()) return;
  for (Pair& pr : pairs) {
    if (!pr.history.touching) continue;
    auto up = pair_velocity<D>(u[pr.i], u[pr.j]);
    if (p.motion[pr.j] == Motion::Mobile) up[D::body] += flow.image_velocity_x(pr.ky, box.ly);
    laws_.advance(pr.history, pair_geometry<D>(p, box, pr), up, dt);
  }
}

template <class D>
void ForceBalanceOf<D>::cap_histories(const Particles& p, const Box& box,
                                      std::vector<Pair>& pairs) const {
  if (!laws_.keeps_history()) return;
  for (Pair& pr : pairs)
    if (pr.history.touching) laws_.cap(pr.history, pair_geometry<D>(p, box, pr));
}

template <class D>
int ForceBalanceOf<D>::stick_reversed_sliding(const Particles& p, std::vector<Pair>& pairs,
                                              const std::vector<Body>& u, double dt,
                                              std::vector<std::size_t>* switched) const {
  (void)p;
  if (switched) switched->clear();
  int changed = 0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    auto& h = pairs[k].history;
    if (!h.touching || !h.contact.sliding) continue;
    const PairTerm& t = terms_[k];
    const auto up = pair_velocity<D>(u[pairs[k].i], u[pairs[k].j] + t.image_j);
    if (contact().stick_after_slip(h.contact, t.g, up, dt)) {
      ++changed;
      if (switched) switched->push_back(k);
    }
  }
  return changed;
}

template <class D>
template <bool kWalls>
void ForceBalanceOf<D>::assemble_pairs(const Particles& p, const Box& box, const ImposedFlow& flow,
                                       const std::vector<Pair>& pairs, double dt_implicit,
                                       const WallBodies* walls) {
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const Pair& pr = pairs[k];
    PairTerm& term = terms_[k];
    term.g = pair_geometry<D>(p, box, pr);
    term.on = laws_.add_blocks(term.g, pr.history, dt_implicit, term.m, term.f, term.sliding);
    if (!term.on) continue;
    term.image_j = Body::Zero();
    Body known = Body::Zero();
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

template <class D>
bool ForceBalanceOf<D>::solve(const Particles& p, const Box& box, const ImposedFlow& flow,
                              const std::vector<Pair>& pairs, double dt_implicit,
                              const WallBodies* walls, Velocities& out) {
  assemble(p, box, flow, pairs, dt_implicit, walls);
  return solve_assembled(p, flow, walls, out);
}

template <class D>
auto ForceBalanceOf<D>::slip_rows(const PairGeometryOf<D>& g, const PairHistoryOf<D>& h) const
    -> std::vector<SlipRow> {
  if constexpr (D::space == 2) {
    (void)h;
    return {{FrictionalContact::slip_mode(g), 1.0}};
  } else {
    // W^T W = sum over an orthonormal basis t_a of the tangent plane of (t_a^T W)^T (t_a^T W):
    // W maps into that plane, and two rows carry it all. Along and across the stretch when the
    // sliding spring already has its share across it.
    const FrictionalContact::SlipMode3 w = FrictionalContact::slip_mode_3d(g);
    const Space3& xi = h.contact.xi;
    const bool sideways = contact().stiff_across(xi);
    const Space3 t1 = sideways ? Space3(xi.normalized()) : Space3(g.n.unitOrthogonal());
    const Space3 t2 = g.n.cross(t1);
    std::vector<SlipRow> rows{{(t1.transpose() * w).transpose(), 1.0}};
    const double across = sideways ? 1.0 - h.contact.across : 1.0;
    if (across > 0.0) rows.push_back({(t2.transpose() * w).transpose(), across});
    return rows;
  }
}

template <class D>
bool ForceBalanceOf<D>::resolve_with_sticking(const Particles& p, const Box& box,
                                              const ImposedFlow& flow,
                                              const std::vector<Pair>& pairs,
                                              const std::vector<std::size_t>& switched,
                                              double dt_implicit, const WallBodies* walls,
                                              Velocities& out) {
  // A fresh assembly reads the contacts' new state when the update would cost more
  // back-substitutions than a factorisation (many switched contacts at large N).
  std::vector<std::vector<SlipRow>> rows_of;
  rows_of.reserve(switched.size());
  std::size_t rows = 0;
  for (std::size_t k : switched) {
    rows_of.push_back(slip_rows(terms_[k].g, pairs[k].history));
    rows += rows_of.back().size();
  }
  const bool over_budget = !system_.low_rank_pays(rows);
  sticking_.switched += static_cast<long>(switched.size());
  if (over_budget) {
    ++sticking_.refactorised_budget;
    return solve(p, box, flow, pairs, dt_implicit, walls, out);
  }
  ++sticking_.low_rank;
  const int d = system_.dof();
  constexpr int B = D::body;
  VecX w, dg;
  for (std::size_t n = 0; n < switched.size(); ++n) {
    const std::size_t k = switched[n];
    const Pair& pr = pairs[k];
    PairTerm& term = terms_[k];
    const double kt_full = dt_implicit * contact().kt_of(term.g);
    const Motion mj = p.motion[pr.j];
    const bool j_mobile = mj == Motion::Mobile, j_floating = mj == Motion::FloatingWall;
    // Known velocity of j's side: the Lees-Edwards image's, the top wall's driven x velocity
    // (a floating wall's y velocity is the unknown V), or zero for a fixed wall.
    const double known_x = j_mobile                                 ? term.image_j.x()
                           : j_floating || mj == Motion::DrivenWall ? walls->driven_vx
                                                                    : 0.0;
    term.sliding = false;
    for (const auto& [row, share] : rows_of[n]) {
      const double kt = share * kt_full;
      // The pair term as a new assembly would make it (stresses read it after the step).
      term.m += kt * row * row.transpose();
      w.setZero(static_cast<Eigen::Index>(system_.unknowns()));
      dg.setZero(w.size());
      const double wj_known = row[B] * known_x;
      for (int r = 0; r < d; ++r) {
        w[d * pr.i + r] = row[r];
        dg[d * pr.i + r] = -kt * row[r] * wj_known;
        if (j_mobile) {
          w[d * pr.j + r] = row[B + r];
          dg[d * pr.j + r] = -kt * row[B + r] * wj_known;
        }
      }
      // The floating wall's y velocity is row[B + 1]'s unknown: its part goes to the border.
      const double w_wall = j_floating ? row[B + 1] : 0.0;
      system_.add_low_rank(w, kt, dg, w_wall, -kt * w_wall * wj_known);
    }
  }
  return solve_assembled(p, flow, walls, out);
}

template <class D>
void ForceBalanceOf<D>::assemble(const Particles& p, const Box& box, const ImposedFlow& flow,
                                 const std::vector<Pair>& pairs, double dt_implicit,
                                 const WallBodies* walls) {
  if (terms_.size() != pairs.size()) throw std::logic_error("ForceBalance: stale pair list");
  if (dt_implicit > 0.0 && diagonal_only_)
    throw std::logic_error("ForceBalance: implicit springs need the coupled pattern");
  system_.clear();
  for (std::size_t i = 0; i < p.n_mobile; ++i) {
    const Body drag = StokesDrag::resistance_of<D>(p.radius[i]);
    Body force = drag.cwiseProduct(flow.velocity(p.position[i]));
    if (!p.external.empty()) force += p.external[i];
    system_.add_self(static_cast<int>(i), drag, force);
  }
  if constexpr (D::space == 2)
    if (fluid_)
      fluid_->assemble(p, flow, system_.dof(), static_cast<int>(system_.particle_unknowns()),
                       system_);
  // Scenes without walls get a loop with no wall branch at all.
  if (walls)
    assemble_pairs<true>(p, box, flow, pairs, dt_implicit, walls);
  else
    assemble_pairs<false>(p, box, flow, pairs, dt_implicit, walls);
}

template <class D>
bool ForceBalanceOf<D>::solve_assembled(const Particles& p, const ImposedFlow& flow,
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

  constexpr int B = D::body;
  const int d = system_.dof();
  out.u.resize(p.size());
  out.wall_v = v;
  if (fluid_) {
    const auto base = static_cast<Eigen::Index>(system_.particle_unknowns());
    out.fluid.assign(u_.data() + base, u_.data() + u_.size());
    out.pressure_gradient = g;  // the multiplier is G itself: the reference's G0 is in g_
  }
  for (std::size_t i = 0; i < p.size(); ++i) {
    Body& ui = out.u[i];
    switch (p.motion[i]) {
      case Motion::Mobile:
        for (int c = 0; c < d; ++c) ui[c] = u_[d * i + c];
        if (d < B) {
          // Without rotational unknowns only drag (and an external torque) acts on omega.
          const Body fluid = fluid_velocity(flow, out, p.position[i]);
          const Body drag = StokesDrag::resistance_of<D>(p.radius[i]);
          for (int c = d; c < B; ++c)
            ui[c] = p.external.empty() ? fluid[c] : fluid[c] + p.external[i][c] / drag[c];
        }
        break;
      case Motion::FixedWall:
        ui.setZero();
        break;
      case Motion::FloatingWall:
        ui.setZero();
        if (walls) ui[0] = walls->driven_vx, ui[1] = v;
        break;
      case Motion::DrivenWall:
        ui.setZero();
        if (walls) ui[0] = walls->driven_vx;
        break;
    }
  }
  return true;
}

template class ForceBalanceOf<Dim2>;
template class ForceBalanceOf<Dim3>;

}  // namespace sheardiff
