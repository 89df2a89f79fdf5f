#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "sheardiff/core/types.hpp"

namespace sheardiff {

// Where a particle's velocity comes from. Mobile particles carry unknowns; a particle of a
// rigid wall body moves with that body (fixed, driven in x, or driven and floating in y;
// core/walls.hpp).
enum class Motion : std::uint8_t { Mobile = 0, FixedWall = 1, FloatingWall = 2, DrivenWall = 3 };

// All discs of a scene. Mobile particles come first (indices 0 .. n_mobile-1), so the
// unknown vector is indexed directly by particle index.
struct Particles {
  std::size_t n_mobile = 0;
  std::vector<Vec2> position;   // current centres (wrapped at neighbour rebuilds)
  std::vector<Vec2> unwrapped;  // centres integrated without wrapping (for displacements)
  // Periodic images crossed at the wraps (x, y), as LAMMPS counts them: position + ix (lx, 0)
  // + iy (le_offset, ly) is continuous in time, Lees-Edwards crossings included (the trajectory's
  // image). Empty until the first wrap (then all zero from the start).
  std::vector<std::array<int, 2>> image;
  std::vector<double> radius;  // a_i = d_i / 2
  std::vector<int> species;    // 0 small, 1 large
  std::vector<Motion> motion;
  std::vector<Vec3> velocity;  // last solved (u_x, u_y, omega)
  // Optional imposed force and torque on mobile particles (empty = none); tests and
  // sedimentation-like scenes use it.
  std::vector<Vec3> external;

  std::size_t size() const { return position.size(); }
  void resize(std::size_t n) {
    position.resize(n, Vec2::Zero());
    unwrapped.resize(n, Vec2::Zero());
    radius.resize(n, 0.5);
    species.resize(n, 0);
    motion.resize(n, Motion::Mobile);
    velocity.resize(n, Vec3::Zero());
  }
};

// Mean centre height of the particles ids (a wall's centre line); 0 for no ids.
inline double mean_height(const Particles& p, const std::vector<int>& ids) {
  double s = 0.0;
  for (int k : ids) s += p.position[static_cast<std::size_t>(k)].y();
  return ids.empty() ? 0.0 : s / static_cast<double>(ids.size());
}

}  // namespace sheardiff
