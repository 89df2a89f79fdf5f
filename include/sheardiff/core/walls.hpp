#pragma once
#include <vector>

namespace sheardiff {

// What a rigid wall body does: stays where it is (fixed), moves in x with the imposed flow at its
// height (driven), or is driven and free in y so that the suspension pushes on it with exactly
// a load (floating).
enum class WallRole { Fixed, Driven, Floating };

// The two rough walls of a wall-bounded scene (indices into Particles). The bottom wall is the
// flow's frame and is fixed; the top wall is what its role says.
struct WallBodies {
  std::vector<int> bottom, top;
  WallRole top_role = WallRole::Floating;
  double load = 0.0;           // floating: P Lx lz
  double free_fall_cap = 1.0;  // floating: |V| bound while nothing (or almost nothing) holds it
  // The x velocity of a driven (or floating) top wall this step: the imposed flow's at its
  // height, taken at the start of each step.
  double driven_vx = 0.0;

  bool floating() const { return top_role == WallRole::Floating; }
};

}  // namespace sheardiff
