#include "sheardiff/observe/run_health.hpp"

#include <fmt/format.h>

#include <cmath>
#include <sstream>

#include "sheardiff/io/atomic_file.hpp"
#include "sheardiff/io/summary_keys.hpp"

namespace sheardiff {

const char* to_string(HealthProblem p) {
  switch (p) {
    case HealthProblem::NonFinite:
      return "non-finite state";
    case HealthProblem::Overlap:
      return "overlap too large";
    case HealthProblem::SolverFailure:
      return "linear solve failed";
    case HealthProblem::Residual:
      return "force balance residual too large";
    case HealthProblem::WallEscape:
      return "top wall escaped";
    case HealthProblem::WallCollapse:
      return "wall gap collapsed";
  }
  return "?";
}

std::string HealthReport::message() const {
  return fmt::format("run health: {} at step {} (strain {:.6g}): {}; {}", to_string(problem), step,
                     strain, what, advice);
}

template <class D>
RunHealthOf<D>::RunHealthOf(const Config& cfg, const Dynamics& d)
    : max_overlap_(cfg.health.max_overlap),
      max_residual_(cfg.health.max_residual),
      explicit_springs_(cfg.integrator.type != IntegratorType::Implicit),
      fixed_dt_(cfg.integrator.dt > 0.0),
      h0_(d.height()) {
  const auto& p = d.particles();
  for (std::size_t i = 0; i < p.n_mobile; ++i) mobile_measure_ += particle_measure<D>(p.radius[i]);
}

template <class D>
double RunHealthOf<D>::max_overlap(const Dynamics& d, std::size_t* pair) {
  const auto& p = d.particles();
  const auto& pairs = d.neighbours().pairs();
  double worst = 0.0;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& pr = pairs[k];
    const auto rij = pair_separation(p, d.box(), pr);
    // Compared squared: a square root per pair only for the few pairs that overlap.
    const double s = p.radius[pr.i] + p.radius[pr.j];
    const double r2 = rij.squaredNorm();
    if (!(r2 < s * s)) continue;
    const double ov = s - std::sqrt(r2);
    if (ov > worst) {
      worst = ov;
      if (pair) *pair = k;
    }
  }
  return worst;
}

template <class D>
HealthReport RunHealthOf<D>::make(HealthProblem problem, const Dynamics& d, std::vector<int> ids,
                                  std::string what) const {
  HealthReport r;
  r.problem = problem;
  r.step = d.steps();
  r.strain = d.strain();
  r.particles = std::move(ids);
  r.what = std::move(what);
  // What to change: the step for explicit or fixed steps, otherwise the accuracy limits.
  std::string step_fix;
  if (fixed_dt_)
    step_fix = explicit_springs_
                   ? "reduce integrator.dt (or set it to 0, adaptive) or use integrator.type = "
                     "\"implicit\""
                   : "reduce integrator.dt or set it to 0 (adaptive)";
  else
    step_fix = explicit_springs_
                   ? "reduce integrator.max_displacement and integrator.explicit_safety, or use "
                     "integrator.type = \"implicit\""
                   : "reduce integrator.max_displacement and integrator.max_overlap_change";
  switch (problem) {
    case HealthProblem::Overlap:
      r.advice = fmt::format(
          "{}, or raise contact.ktilde (softer springs overlap more); the "
          "limit is health.max_overlap",
          step_fix);
      break;
    case HealthProblem::Residual:
      r.advice = fmt::format(
          "the system is ill-conditioned: {}, raise lubrication.delta, or try "
          "solver.cholesky = \"eigen\"; the limit is health.max_residual",
          step_fix);
      break;
    case HealthProblem::WallEscape:
    case HealthProblem::WallCollapse:
      r.advice = fmt::format("{}, or reduce walls.free_fall_speed", step_fix);
      break;
    case HealthProblem::NonFinite:
    case HealthProblem::SolverFailure:
      r.advice = step_fix;
      break;
  }
  return r;
}

namespace {

std::string id_list(const std::vector<int>& ids) {
  std::string s;
  for (std::size_t k = 0; k < ids.size(); ++k) s += (k ? ", " : "") + std::to_string(ids[k]);
  return s;
}

}  // namespace

template <class D>
std::optional<HealthReport> RunHealthOf<D>::check(const Dynamics& d, const Velocities& v,
                                                  double dt) {
  const auto& p = d.particles();
  std::vector<int> bad;
  for (std::size_t i = 0; i < p.size() && bad.size() < 10; ++i)
    if (!p.position[i].allFinite() || (i < v.u.size() && !v.u[i].allFinite()))
      bad.push_back(static_cast<int>(i));
  if (!bad.empty() || !std::isfinite(v.wall_v) || !std::isfinite(d.time())) {
    auto r = make(HealthProblem::NonFinite, d, bad,
                  bad.empty() ? std::string("the top wall velocity or the time is not finite")
                              : fmt::format("position or velocity not finite for particle(s) {}",
                                            id_list(bad)));
    r.state_finite = false;
    return r;
  }

  std::size_t k = 0;
  const double ov = max_overlap(d, &k);
  max_overlap_seen_ = std::max(max_overlap_seen_, ov);
  if (ov > max_overlap_) {
    const auto& pr = d.neighbours().pairs()[k];
    return make(HealthProblem::Overlap, d, {pr.i, pr.j},
                fmt::format("particles {} and {} overlap by {:.3g} d > health.max_overlap = {} d",
                            pr.i, pr.j, ov, max_overlap_));
  }

  // Only a factorised system has a residual worth checking (a diagonal one is exact).
  const double res = d.force_balance().last_residual();
  max_residual_seen_ = std::max(max_residual_seen_, res);
  if (!(res <= max_residual_))
    return make(HealthProblem::Residual, d, {},
                fmt::format("relative residual |A U - F| / |F| = {:.3g} > health.max_residual = {}",
                            res, max_residual_));

  if (d.walls()) {
    const double h = d.height();
    const double section = band_section(d);
    // A packing fills at most ~0.9 of the gap between the wall centre rows: all of it means
    // the particles overlap massively or went through a wall.
    if (!(mobile_measure_ < section * h))
      return make(HealthProblem::WallCollapse, d, d.walls()->top,
                  fmt::format("wall gap H = {:.4g} d (initially {:.4g} d) is smaller than the "
                              "particles' {} over {} = {:.4g} d",
                              h, h0_, D::space == 3 ? "volume" : "area",
                              D::space == 3 ? "Lx Lz" : "Lx", mobile_measure_ / section));
    // The step limits move the wall by ~1e-3 d per step; half a diameter in one step, or a
    // gap doubled with a gas-like packing (phi < 0.1), means it was thrown off.
    const double jump = v.wall_v * dt;
    if (std::abs(jump) > 0.5 || (h > 2.0 * h0_ && mobile_measure_ < 0.1 * section * h))
      return make(jump < 0.0 ? HealthProblem::WallCollapse : HealthProblem::WallEscape, d,
                  d.walls()->top,
                  fmt::format("the top wall moved {:+.3g} d in one step (more than 0.5 d); gap "
                              "H = {:.4g} d (initially {:.4g} d)",
                              jump, h, h0_));
    // A mobile disc beyond a wall row went through it.
    const double top = mean_height(p, d.walls()->top), bottom = mean_height(p, d.walls()->bottom);
    for (std::size_t i = 0; i < p.n_mobile; ++i) {
      const double y = p.position[i].y();
      if (y < bottom - 2.0 * p.radius[i] || y > top + 2.0 * p.radius[i])
        return make(HealthProblem::WallEscape, d, {static_cast<int>(i)},
                    fmt::format("particle {} at y = {:.4g} d went through a wall (walls at "
                                "{:.4g} and {:.4g} d)",
                                i, y, bottom, top));
    }
  }
  return std::nullopt;
}

template <class D>
HealthReport RunHealthOf<D>::solver_failure(const Dynamics& d, const Velocities& v) const {
  std::size_t k = 0;
  const double ov = max_overlap(d, &k);
  std::vector<int> ids;
  if (ov > 0.0) ids = {d.neighbours().pairs()[k].i, d.neighbours().pairs()[k].j};
  auto r = make(HealthProblem::SolverFailure, d, ids,
                fmt::format("the resistance matrix is not positive definite or the solved "
                            "velocities are not finite (largest overlap {:.3g} d{})",
                            ov, ids.empty() ? "" : ", particles " + id_list(ids)));
  r.state_finite = true;
  for (std::size_t i = 0; i < d.particles().size(); ++i)
    r.state_finite = r.state_finite && d.particles().position[i].allFinite();
  (void)v;
  return r;
}

template <class D>
void RunHealthOf<D>::report(nlohmann::json& js) const {
  js[summary_key::health] = {{"max_overlap", max_overlap_seen_},
                             {"max_residual", max_residual_seen_},
                             {"max_overlap_limit", max_overlap_},
                             {"max_residual_limit", max_residual_}};
}

template <class D>
void write_diagnostic(const std::filesystem::path& file, const DynamicsOf<D>& d,
                      const VelocitiesOf<D>& v, const HealthReport& r) {
  std::ostringstream out;
  out << "# sheardiff diagnostic frame: the state at which the run health check stopped the run\n"
      << "# problem: " << to_string(r.problem) << "\n# step: " << r.step
      << "\n# strain: " << fmt::format("{:.17g}", r.strain) << "\n# what: " << r.what
      << "\n# advice: " << r.advice << "\n# particles:";
  for (int i : r.particles) out << ' ' << i;
  out << fmt::format("\n# box: lx = {:.17g}, ly = {:.17g}, height = {:.17g}\n", d.box().lx,
                     d.box().ly, d.height());
  out << (D::space == 3 ? "# id x y z diameter ux uy uz omega_x omega_y omega_z motion flagged\n"
                        : "# id x y diameter ux uy omega motion flagged\n");
  const auto& p = d.particles();
  using Body = typename D::Body;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Body u = i < v.u.size() ? v.u[i] : Body::Zero();
    const bool flagged =
        std::find(r.particles.begin(), r.particles.end(), static_cast<int>(i)) != r.particles.end();
    out << i;
    for (int c = 0; c < D::space; ++c) out << fmt::format(" {:.17g}", p.position[i](c));
    out << fmt::format(" {:.17g}", 2.0 * p.radius[i]);
    for (int c = 0; c < D::body; ++c) out << fmt::format(" {:.17g}", u(c));
    out << fmt::format(" {} {}\n", static_cast<int>(p.motion[i]), flagged ? 1 : 0);
  }
  write_file_atomically(file, out.str());
}

template class RunHealthOf<Dim2>;
template class RunHealthOf<Dim3>;
template void write_diagnostic(const std::filesystem::path&, const Dynamics&, const Velocities&,
                               const HealthReport&);
template void write_diagnostic(const std::filesystem::path&, const Dynamics3&,
                               const VelocitiesOf<Dim3>&, const HealthReport&);

}  // namespace sheardiff
