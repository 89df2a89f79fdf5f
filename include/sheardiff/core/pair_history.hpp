#pragma once
// What one listed pair carries from step to step, as state (the neighbour list keeps it, the
// pair laws read and advance it; interactions/pair_laws.hpp maps each law to its member). A law
// that keeps a per-contact history adds one member here.

#include <type_traits>

#include "sheardiff/core/dimension.hpp"

namespace sheardiff {

// The tangential spring of a frictional contact (interactions/contact.hpp is its law).
struct TangentialSpring {
  double xi = 0.0;       // scalar tangential spring stretch (2D)
  bool sliding = false;  // the last step capped xi at the Coulomb limit
};

// The same between two spheres: a vector in the plane normal to the line of centres.
struct TangentialSpring3 {
  Space3 xi = Space3::Zero();
  bool sliding = false;
  // The spring's stiffness across xi over kt that its last cap left: cap / |xi before the cap|
  // when it slid, 1 when it stuck (FrictionalContact::cap; contact.sliding_stiffness).
  double across = 1.0;
};

// Whether the pair touches (decided at the start of a step, shared by every law) and the
// history of each law that keeps one. Trivially copyable: it is checkpointed as raw bytes with
// the neighbour list.
struct PairHistory {
  bool touching = false;
  TangentialSpring contact;
};
struct PairHistory3 {
  bool touching = false;
  TangentialSpring3 contact;
};

template <class D>
using PairHistoryOf = std::conditional_t<D::space == 2, PairHistory, PairHistory3>;

}  // namespace sheardiff
