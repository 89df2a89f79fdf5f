// Pressure-driven channel flow (Nott & Brady 1994): monodisperse discs between two fixed,
// straight rows of touching wall discs, periodic in x, pumped at a fixed mean velocity <u>.
// Geometry and fluid in docs/channel.md.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "sheardiff/scene/scene.hpp"

namespace sheardiff {

namespace {

// The seed's start: the discs on a regular (staggered) array between the walls, then random
// displacements until the array is forgotten (Metropolis moves of hard discs, all accepted
// unless they overlap a disc or a wall).
std::vector<Vec2> lattice_then_shuffle(std::size_t n, double lx, double y_min, double y_max,
                                       double wall_lo, double wall_hi, std::mt19937_64& rng) {
  const double d = 1.0, clearance = 1.0 + 1e-3;
  const int columns = std::max(1, static_cast<int>(std::floor(lx / clearance)));
  const int rows = static_cast<int>((n + columns - 1) / columns);
  const double sx = lx / columns;
  const double sy = rows > 1 ? (y_max - y_min) / (rows - 1) : 0.0;
  if (rows > 1 && (std::hypot(0.5 * sx, sy) < clearance || y_max < y_min))
    throw ConfigError(fmt::format(
        "channel.phi: {} discs do not fit between the walls on a staggered array ({} rows of {}); "
        "lower channel.phi or raise channel.h_over_a",
        n, rows, columns));
  std::vector<Vec2> sites;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c)
      sites.emplace_back((c + 0.5 + 0.5 * (r % 2)) * sx,
                         rows > 1 ? y_min + r * sy : 0.5 * (y_min + y_max));
  std::shuffle(sites.begin(), sites.end(), rng);
  std::vector<Vec2> x(sites.begin(), sites.begin() + static_cast<long>(n));
  // Overlap with another disc (periodic in x) or a wall row (centre lines wall_lo, wall_hi).
  const auto free_at = [&](std::size_t i, const Vec2& y) {
    if (y.y() < y_min || y.y() > y_max) return false;
    for (double wl : {wall_lo, wall_hi}) {
      const double dy = y.y() - wl;
      if (std::abs(dy) >= d) continue;
      // Nearest wall disc centre: the row has one every d starting at d / 2.
      double dx = std::remainder(y.x() - 0.5 * d, d);
      if (dx * dx + dy * dy < clearance * clearance) return false;
    }
    for (std::size_t j = 0; j < x.size(); ++j) {
      if (j == i) continue;
      const double dx = std::remainder(y.x() - x[j].x(), lx), dy = y.y() - x[j].y();
      if (dx * dx + dy * dy < clearance * clearance) return false;
    }
    return true;
  };
  std::uniform_real_distribution<double> step(-0.25, 0.25);
  for (int sweep = 0; sweep < 400; ++sweep)
    for (std::size_t i = 0; i < n; ++i) {
      Vec2 y = x[i] + Vec2(step(rng), step(rng));
      y.x() -= lx * std::floor(y.x() / lx);
      if (free_at(i, y)) x[i] = y;
    }
  return x;
}

}  // namespace

Scene build_channel(const Config& cfg) {
  const auto& ch = cfg.channel;
  const double a = 0.5, d = 1.0;
  const double lx = static_cast<double>(ch.wall_discs) * d;
  const double height = ch.h_over_a * a;
  // Wall rows: centre lines at 0 and H + 2a, so that their surfaces are H apart.
  const double wall_lo = 0.0, wall_hi = height + 2.0 * a;
  const double y_lo = wall_lo + a, y_hi = wall_hi - a;
  const auto n =
      static_cast<std::size_t>(std::llround(ch.phi * lx * height / (std::numbers::pi * a * a)));

  std::mt19937_64 rng(static_cast<std::uint64_t>(cfg.run.seed) ^ 0x2545f4914f6cdd1dULL);
  // Mobile centres at least one diameter from both wall centre lines (the array's rows).
  const std::vector<Vec2> x =
      lattice_then_shuffle(n, lx, wall_lo + d * 1.001, wall_hi - d * 1.001, wall_lo, wall_hi, rng);

  Scene sc;
  const auto nw = static_cast<std::size_t>(ch.wall_discs);
  sc.particles.resize(n + 2 * nw);
  sc.particles.n_mobile = n;
  for (std::size_t i = 0; i < n; ++i) sc.particles.position[i] = x[i];
  WallBodies walls;
  walls.top_role = WallRole::Fixed;
  for (std::size_t k = 0; k < 2 * nw; ++k) {
    const bool top = k >= nw;
    const std::size_t i = n + k;
    sc.particles.position[i] =
        Vec2((static_cast<double>(k % nw) + 0.5) * d, top ? wall_hi : wall_lo);
    sc.particles.motion[i] = Motion::FixedWall;
    (top ? walls.top : walls.bottom).push_back(static_cast<int>(i));
  }
  for (double& r : sc.particles.radius) r = a;
  sc.particles.unwrapped = sc.particles.position;

  sc.box.lx = lx;
  sc.box.ly = wall_hi + 2.0 * a;
  sc.box.lees_edwards = false;
  // The reference flow: Poiseuille between the wall surfaces with mean velocity <u>; the clock
  // counts a / <u>.
  const double u = ch.mean_velocity;
  sc.flow.y0 = y_lo;
  sc.flow.span = height;
  sc.flow.gammadot = 6.0 * u / height;
  sc.flow.curvature = -6.0 * u / (height * height);
  sc.flow.rate = u / a;
  sc.walls = std::move(walls);
  if (ch.coupling == "two_way") {
    // By default one element per a/2, the seed's profile bins.
    const auto cells = ch.fluid_cells > 0
                           ? ch.fluid_cells
                           : std::max<std::int64_t>(4, std::llround(2.0 * ch.h_over_a));
    sc.fluid =
        FluidGrid{y_lo, y_hi, static_cast<int>(cells), lx, cfg.flow.lz, 0.5 * cfg.neighbour.skin};
  }
  return sc;
}

std::optional<ConfigProblem> check_channel(const Config& c) {
  const ChannelParams& ch = c.channel;
  if (c.particles.size_ratio != 1.0)
    return ConfigProblem{
        "particles.size_ratio",
        fmt::format("{:g}: the channel scene is monodisperse (the seed's spheres); set 1",
                    c.particles.size_ratio)};
  if (c.analysis.diffusion)
    return ConfigProblem{"analysis.diffusion",
                         "the channel has no imposed shear rate to scale the diffusion analysis "
                         "by; set false (the channel's own profiles and time series are always "
                         "written)"};
  if (ch.fluid_cells != 0 && ch.fluid_cells < 4)
    return ConfigProblem{"channel.fluid_cells",
                         fmt::format("{}: at least 4 elements across the channel", ch.fluid_cells)};
  if (!c.particles.init_file.empty())
    return ConfigProblem{"particles.init_file",
                         "the channel scene places its discs itself (the seed's lattice and "
                         "Monte Carlo start); leave it empty"};
  const double interior =
      ch.phi * static_cast<double>(ch.wall_discs) * 2.0 * ch.h_over_a / std::numbers::pi;
  if (std::llround(interior) < 1)
    return ConfigProblem{
        "channel.phi", fmt::format("{:g} puts no disc in a channel of {} wall discs and H/a = {:g}",
                                   ch.phi, ch.wall_discs, ch.h_over_a)};
  return std::nullopt;
}

// One frame per row of the profile history, in a / <u>.
double channel_frame_spacing(const Config& c) {
  return std::min(c.channel.sample_interval, c.run.strain);
}

// Lx = wall_discs d; H = h_over_a a between the wall rows' surfaces.
PlannedCell channel_cell(const Config& c) {
  return {static_cast<double>(c.channel.wall_discs), 0.5 * c.channel.h_over_a};
}

}  // namespace sheardiff
