#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "sheardiff/core/dimension.hpp"

namespace sheardiff {

// Where a particle's velocity comes from. Mobile particles carry unknowns; a particle of a
// rigid wall body moves with that body (fixed, driven in x, or driven and floating in y;
// core/walls.hpp).
enum class Motion : std::uint8_t { Mobile = 0, FixedWall = 1, FloatingWall = 2, DrivenWall = 3 };

// All particles of a scene: discs of a monolayer (D = Dim2) or spheres (Dim3). Mobile particles
// come first (indices 0 .. n_mobile-1), so the unknown vector is indexed directly by particle
// index.
template <class D>
struct ParticlesOf {
  using Point = typename D::Point;
  using Body = typename D::Body;

  std::size_t n_mobile = 0;
  std::vector<Point> position;   // current centres (wrapped at neighbour rebuilds)
  std::vector<Point> unwrapped;  // centres integrated without wrapping (for displacements)
  // Periodic images crossed at the wraps (x, y[, z]), as LAMMPS counts them: position + ix (lx,
  // 0) + iy (le_offset, ly) [+ iz (0, 0, lz)] is continuous in time, Lees-Edwards crossings
  // included (the trajectory's image). Empty until the first wrap (then all zero from the start).
  std::vector<typename D::Images> image;
  std::vector<double> radius;  // a_i = d_i / 2
  std::vector<int> species;    // 0 small, 1 large
  std::vector<Motion> motion;
  std::vector<Body> velocity;  // last solved (u, omega): (u_x, u_y, omega_z) in 2D
  // Optional imposed force and torque on mobile particles (empty = none); tests and
  // sedimentation-like scenes use it.
  std::vector<Body> external;

  std::size_t size() const { return position.size(); }
  void resize(std::size_t n) {
    position.resize(n, Point::Zero());
    unwrapped.resize(n, Point::Zero());
    radius.resize(n, 0.5);
    species.resize(n, 0);
    motion.resize(n, Motion::Mobile);
    velocity.resize(n, Body::Zero());
  }
};

using Particles = ParticlesOf<Dim2>;
using Particles3 = ParticlesOf<Dim3>;

// Mean centre height of the particles ids (a wall's centre line); 0 for no ids.
template <class D>
double mean_height(const ParticlesOf<D>& p, const std::vector<int>& ids) {
  double s = 0.0;
  for (int k : ids) s += p.position[static_cast<std::size_t>(k)].y();
  return ids.empty() ? 0.0 : s / static_cast<double>(ids.size());
}

}  // namespace sheardiff
