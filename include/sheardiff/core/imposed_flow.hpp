#pragma once
#include <algorithm>
#include <cmath>

#include "sheardiff/core/types.hpp"

namespace sheardiff {

// The background flow a scene imposes (docs/model.md section 3): the fluid velocity and its
// gradient as functions of position, and the clock the run is measured in. Everything the
// engine needs from the flow goes through these members: the drag's right-hand side, the
// non-affine motion, the Lees-Edwards images, the velocity of driven walls, the step bound
// integrator.max_strain_step and the run's length run.strain.
//
// The flows the scenes impose are a simple shear, v = (gammadot (y - y0), 0), omega = -gammadot /
// 2, measured in strain gammadot t, and a plane Poiseuille flow between fixed walls, v_x = (y - y0)
// (gammadot + curvature (y - y0)), measured in the channel's time <u> t / a.
struct ImposedFlow {
  double gammadot = 0.0;   // dv_x/dy at y0
  double y0 = 0.0;         // height at which the fluid is at rest (a fixed bottom wall's line)
  double curvature = 0.0;  // (1/2) d2v_x/dy2: 0 for a shear
  double span = 0.0;       // a curved profile is used between y0 and y0 + span
  double rate = 0.0;       // the clock's rate; 0: the shear rate gammadot (strain)

  // (v_x, v_y, omega) of the fluid at x.
  Vec3 velocity(const Vec2& x) const {
    const double dy = x.y() - y0;
    return {dy * (gammadot + curvature * dy), 0.0, -0.5 * (gammadot + 2.0 * curvature * dy)};
  }
  // Spheres: (v, omega) of the fluid at x; the flow is in x, varies in y, turns about z.
  Vec6 velocity(const Space3& x) const {
    const Vec3 plane = velocity(Vec2(x.x(), x.y()));
    Vec6 v;
    v << plane.x(), plane.y(), 0.0, 0.0, 0.0, plane.z();
    return v;
  }
  // grad v at x, (grad v)_ab = d v_a / d x_b.
  Mat2 gradient(const Vec2& x) const {
    Mat2 g;
    g << 0.0, gammadot + 2.0 * curvature * (x.y() - y0), 0.0, 0.0;
    return g;
  }
  // The run's clock at time t (strain, or <u> t / a) and its rate; a step advances it by at
  // most integrator.max_strain_step.
  double clock(double time) const { return clock_rate() * time; }
  double clock_rate() const { return rate > 0.0 ? rate : gammadot; }
  // The largest |dv_x/dy| of the flow (over y0 .. y0 + span for a curved profile): how fast
  // the flow can carry listed pairs apart.
  double max_shear_rate() const {
    return std::max(std::abs(gammadot), std::abs(gammadot + 2.0 * curvature * span));
  }
  // The x velocity of the periodic image ky cells of height ly up, relative to the cell:
  // the fluid's velocity difference across ky ly (Lees-Edwards).
  double image_velocity_x(int ky, double ly) const { return ky * gammadot * ly; }
};

}  // namespace sheardiff
