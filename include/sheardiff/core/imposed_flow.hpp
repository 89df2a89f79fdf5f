#pragma once
#include "sheardiff/core/types.hpp"

namespace sheardiff {

// The background flow a scene imposes (docs/model.md section 3): the fluid velocity and its
// gradient as functions of position, and the clock the run is measured in. Everything the
// engine needs from the flow goes through these members: the drag's right-hand side, the
// non-affine motion, the Lees-Edwards images, the velocity of driven walls, the step bound
// integrator.max_strain_step and the run's length run.strain.
//
// The flows the scenes impose are simple shears, v = (gammadot (y - y0), 0), omega = -gammadot / 2,
// measured in strain gammadot t.
struct ImposedFlow {
  double gammadot = 0.0;
  double y0 = 0.0;  // height at which the fluid is at rest (a fixed bottom wall's centre line)

  // (v_x, v_y, omega) of the fluid at x.
  Vec3 velocity(const Vec2& x) const { return {gammadot * (x.y() - y0), 0.0, -0.5 * gammadot}; }
  // grad v at x, (grad v)_ab = d v_a / d x_b.
  Mat2 gradient(const Vec2&) const {
    Mat2 g;
    g << 0.0, gammadot, 0.0, 0.0;
    return g;
  }
  // The run's clock at time t (strain) and its rate; a step advances it by at most
  // integrator.max_strain_step.
  double clock(double time) const { return gammadot * time; }
  double clock_rate() const { return gammadot; }
  // The x velocity of the periodic image ky cells of height ly up, relative to the cell:
  // the fluid's velocity difference across ky ly (Lees-Edwards).
  double image_velocity_x(int ky, double ly) const { return ky * gammadot * ly; }
};

}  // namespace sheardiff
