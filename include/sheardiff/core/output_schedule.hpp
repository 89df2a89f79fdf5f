#pragma once
#include <cmath>
#include <limits>

namespace sheardiff {

// The next output strain (frame, checkpoint, analysis sample) after `strain`: `next` advanced by
// whole `spacing`s, as repeated addition does, but in bounded time whatever the spacing. An
// output is due at the first step whose strain reaches it (within 1e-12 relative).
inline double next_output_strain(double next, double spacing, double strain) {
  const double until = strain * (1.0 + 1e-12);
  // A spacing far below one step (a Config made in code is not range checked): skip ahead
  // instead of adding it billions of times.
  if (next <= until && (until - next) / spacing > 1e6)
    next += std::floor((until - next) / spacing) * spacing;
  while (next <= until) {
    const double after = next + spacing;
    if (!(after > next)) return std::nextafter(until, std::numeric_limits<double>::infinity());
    next = after;
  }
  return next;
}

inline bool output_due(double next, double strain) {
  return strain >= next * (1.0 - 1e-12);
}

}  // namespace sheardiff
