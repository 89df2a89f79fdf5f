#include "sheardiff/analysis/power_law.hpp"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sheardiff {
namespace {

void check_sizes(const char* who, std::size_t nx, std::size_t ny, std::size_t min_points) {
  if (nx != ny) {
    throw std::invalid_argument(fmt::format("{}: x has {} values but y has {}", who, nx, ny));
  }
  if (nx < min_points) {
    throw std::invalid_argument(
        fmt::format("{}: need at least {} points, got {}", who, min_points, nx));
  }
}

std::vector<double> logs(const char* who, const char* name, const std::vector<double>& v) {
  std::vector<double> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!(v[i] > 0.0) || !std::isfinite(v[i])) {
      throw std::invalid_argument(fmt::format(
          "{}: {}[{}] = {} must be positive and finite for a log-log fit", who, name, i, v[i]));
    }
    out[i] = std::log(v[i]);
  }
  return out;
}

// Residual sum of squares of the log-log line fit of (phi_c - phi) against x; +inf when
// phi_c <= max(phi) so a minimiser never steps there.
double loglog_ssr(const std::vector<double>& logx, const std::vector<double>& phi, double phi_c) {
  const double n = static_cast<double>(logx.size());
  double mx = 0, my = 0;
  std::vector<double> ly(phi.size());
  for (std::size_t i = 0; i < phi.size(); ++i) {
    const double gap = phi_c - phi[i];
    if (!(gap > 0.0)) return INFINITY;
    ly[i] = std::log(gap);
    mx += logx[i];
    my += ly[i];
  }
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < ly.size(); ++i) {
    const double dx = logx[i] - mx, dy = ly[i] - my;
    sxx += dx * dx;
    sxy += dx * dy;
    syy += dy * dy;
  }
  // Syy - Sxy^2/Sxx is the OLS residual; clamp the roundoff of a perfect fit.
  return std::max(0.0, syy - sxy * sxy / sxx);
}

}  // namespace

LineFit fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  check_sizes("fit_line", x.size(), y.size(), 3);
  const std::size_t m = x.size();
  for (std::size_t i = 0; i < m; ++i) {
    if (!std::isfinite(x[i]) || !std::isfinite(y[i])) {
      throw std::invalid_argument(fmt::format("fit_line: non-finite value at index {}", i));
    }
  }
  const double n = static_cast<double>(m);
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < m; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  // Centred sums: no cancellation when x sits far from 0 (e.g. log x ~ -7).
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const double dx = x[i] - mx, dy = y[i] - my;
    sxx += dx * dx;
    sxy += dx * dy;
    syy += dy * dy;
  }
  if (!(sxx > 0.0)) throw std::invalid_argument("fit_line: all x values are equal");
  LineFit f;
  f.n = static_cast<long>(m);
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  for (std::size_t i = 0; i < m; ++i) {
    const double r = y[i] - (f.intercept + f.slope * x[i]);
    f.ssr += r * r;
  }
  const double s2 = f.ssr / (n - 2.0);
  f.slope_stderr = std::sqrt(s2 / sxx);
  f.intercept_stderr = std::sqrt(s2 * (1.0 / n + mx * mx / sxx));
  f.r2 = syy > 0.0 ? 1.0 - f.ssr / syy : 1.0;
  return f;
}

PowerLawFit fit_power_law(const std::vector<double>& x, const std::vector<double>& g) {
  check_sizes("fit_power_law", x.size(), g.size(), 3);
  const LineFit line = fit_line(logs("fit_power_law", "x", x), logs("fit_power_law", "g", g));
  PowerLawFit p;
  p.a = std::exp(line.intercept);
  p.b = line.slope;
  p.a_stderr = p.a * line.intercept_stderr;  // first-order propagation through exp
  p.b_stderr = line.slope_stderr;
  p.n = line.n;
  p.r2 = line.r2;
  return p;
}

namespace {

// The log of phi_c - max(phi) that best makes phi_c - phi a power law of x.
double best_log_gap(const std::vector<double>& logx, const std::vector<double>& phi,
                    double phi_max) {
  // (1) Search over u = log(phi_c - phi_max): the optimum can sit very close to max(phi) (a
  // small-x point with phi_c - phi ~ 1e-3), which a linear grid would resolve poorly. Gaps
  // below 1e-9 are not searched (far below any measurable phi).
  const double u_lo = std::log(1e-9), u_hi = std::log(0.5);
  const auto cost = [&](double u) { return loglog_ssr(logx, phi, phi_max + std::exp(u)); };
  // The first local minimum above max(phi) is taken, not the global one: for phi_c >> phi,
  // log(phi_c - phi) ~ log(phi_c) - phi / phi_c is nearly linear in phi, so for data that are not
  // an exact power law the residual can fall again towards the end of the range (a degenerate
  // fit with b -> 0 and phi_c at the search bound, seen on measured sweeps: docs/results.md).
  // Only without an interior minimum is the global one used.
  constexpr int kGrid = 400;
  std::vector<double> grid_cost(kGrid);
  for (int j = 0; j < kGrid; ++j) grid_cost[j] = cost(u_lo + (u_hi - u_lo) * j / (kGrid - 1));
  int best =
      static_cast<int>(std::min_element(grid_cost.begin(), grid_cost.end()) - grid_cost.begin());
  for (int j = 1; j + 1 < kGrid; ++j) {
    if (grid_cost[j] < grid_cost[j - 1] && grid_cost[j] <= grid_cost[j + 1]) {
      best = j;
      break;
    }
  }
  const double best_cost = grid_cost[best];
  // Golden section inside the grid cell pair bracketing the best grid point.
  const double step = (u_hi - u_lo) / (kGrid - 1);
  double a = u_lo + step * std::max(best - 1, 0);
  double b = u_lo + step * std::min(best + 1, kGrid - 1);
  const double inv_golden = 0.5 * (std::sqrt(5.0) - 1.0);
  double c1 = b - inv_golden * (b - a), c2 = a + inv_golden * (b - a);
  double f1 = cost(c1), f2 = cost(c2);
  while (b - a > 1e-12) {
    if (f1 < f2) {
      b = c2;
      c2 = c1;
      f2 = f1;
      c1 = b - inv_golden * (b - a);
      f1 = cost(c1);
    } else {
      a = c1;
      c1 = c2;
      f1 = f2;
      c2 = a + inv_golden * (b - a);
      f2 = cost(c2);
    }
  }
  double u_best = 0.5 * (a + b);
  // Keep the grid point if the refinement somehow did worse (flat or noisy objective).
  if (cost(u_best) > best_cost) u_best = u_lo + step * best;
  return u_best;
}

// Joint standard errors of (phi_c, a, b) into fit, from the linearised covariance.
void joint_errors(DilatancyFit& fit, const std::vector<double>& logx,
                  const std::vector<double>& gap) {
  // Joint covariance of (phi_c, log a, b) for the residual r_i = log(phi_c - phi_i) - log a -
  // b log x_i, linearised at the optimum.
  const std::size_t m = gap.size();
  Eigen::MatrixXd jac(static_cast<Eigen::Index>(m), 3);
  double ssr = 0;
  const double log_a = std::log(fit.law.a);
  for (std::size_t i = 0; i < m; ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    jac(r, 0) = 1.0 / gap[i];
    jac(r, 1) = -1.0;
    jac(r, 2) = -logx[i];
    const double res = std::log(gap[i]) - log_a - fit.law.b * logx[i];
    ssr += res * res;
  }
  const Eigen::Matrix3d jtj = jac.transpose() * jac;
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(jtj);
  if (lu.isInvertible()) {
    const Eigen::Matrix3d cov = (ssr / static_cast<double>(m - 3)) * lu.inverse();
    fit.phi_c_stderr = std::sqrt(std::max(0.0, cov(0, 0)));
    fit.a_stderr_joint = fit.law.a * std::sqrt(std::max(0.0, cov(1, 1)));
    fit.b_stderr_joint = std::sqrt(std::max(0.0, cov(2, 2)));
  } else {
    // Degenerate design (e.g. the gap's log is collinear with log x): no finite error.
    fit.phi_c_stderr = fit.a_stderr_joint = fit.b_stderr_joint =
        std::numeric_limits<double>::quiet_NaN();
  }
}

}  // namespace

DilatancyFit fit_dilatancy(const std::vector<double>& x, const std::vector<double>& phi) {
  check_sizes("fit_dilatancy", x.size(), phi.size(), 4);
  const std::vector<double> logx = logs("fit_dilatancy", "x", x);
  for (std::size_t i = 0; i < phi.size(); ++i) {
    if (!std::isfinite(phi[i])) {
      throw std::invalid_argument(fmt::format("fit_dilatancy: phi[{}] is not finite", i));
    }
  }
  if (*std::min_element(x.begin(), x.end()) == *std::max_element(x.begin(), x.end())) {
    throw std::invalid_argument("fit_dilatancy: all x values are equal");
  }
  const double phi_max = *std::max_element(phi.begin(), phi.end());

  // (1) phi_c, searched above max(phi).
  DilatancyFit fit;
  fit.phi_c = phi_max + std::exp(best_log_gap(logx, phi, phi_max));

  // (2) Power law of the gap at fixed phi_c.
  std::vector<double> gap(phi.size());
  for (std::size_t i = 0; i < phi.size(); ++i) gap[i] = fit.phi_c - phi[i];
  fit.law = fit_power_law(x, gap);

  // (3) Least-squares phi_c at fixed a, b: minimising sum (phi_c - a x^b - phi)^2 in phi_c gives
  // the mean of phi + a x^b; its shift from (1) is the seed's error estimate.
  double refit = 0;
  for (std::size_t i = 0; i < phi.size(); ++i) {
    refit += phi[i] + fit.law.a * std::pow(x[i], fit.law.b);
  }
  refit /= static_cast<double>(phi.size());
  fit.phi_c_err = std::abs(refit - fit.phi_c);

  joint_errors(fit, logx, gap);
  return fit;
}

}  // namespace sheardiff
