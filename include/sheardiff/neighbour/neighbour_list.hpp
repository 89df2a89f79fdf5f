#pragma once
#include <cstddef>
#include <vector>

#include "sheardiff/core/archive.hpp"
#include "sheardiff/core/box.hpp"
#include "sheardiff/core/pair_history.hpp"
#include "sheardiff/core/particles.hpp"

namespace sheardiff {

// One listed pair. i is always mobile; j is mobile or a wall particle. j is seen through the
// periodic image (kx, ky) of the box. Wall-wall pairs are never listed. history: what the pair
// laws keep for it from step to step (core/pair_history.hpp), carried while the pair touches.
struct Pair {
  int i = 0, j = 0;
  int kx = 0, ky = 0;
  PairHistory history;
};

// The vector from i to (the image of) j of a listed pair, at the current positions and offset.
inline Vec2 pair_separation(const Particles& p, const Box& box, const Pair& pr) {
  return p.position[pr.j] + box.image_shift(pr.kx, pr.ky) - p.position[pr.i];
}

// Verlet list built with a nanoflann k-d tree over the particles and their periodic
// (and Lees-Edwards shifted) images. Every pair within s (1 + h_max/2) + skin is listed;
// the list stays valid until the non-affine motion plus the affine shear of a pair can
// have used up the skin.
class NeighbourList {
 public:
  NeighbourList(double interaction_range_factor, double skin)
      : range_factor_(interaction_range_factor), skin_(skin) {}

  // Wraps positions into the box, rebuilds the list, and carries the history of touching
  // pairs that are still listed.
  void rebuild(Particles& p, const Box& box);
  // Accumulate the motion since the last rebuild; na = non-affine displacement of each
  // particle in this step, dstrain = gammadot dt.
  void advance(const std::vector<Vec2>& na_displacement, double dstrain);
  bool needs_rebuild() const;

  const std::vector<Pair>& pairs() const { return pairs_; }
  std::vector<Pair>& pairs() { return pairs_; }
  std::size_t rebuilds() const { return rebuilds_; }
  double skin() const { return skin_; }
  void serialize(Archive& a) {
    a.io(pairs_);
    a.io(na_since_build_);
    a.io(strain_since_build_);
    a.io(max_cutoff_);
    a.io(rebuilds_);
  }
  // Pair cut-off distance for radii ai, aj.
  double cutoff(double ai, double aj) const { return (ai + aj) * range_factor_ + skin_; }

 private:
  double range_factor_;
  double skin_;
  std::vector<Pair> pairs_;
  std::vector<Vec2> na_since_build_;
  double strain_since_build_ = 0.0;
  double max_cutoff_ = 0.0;
  std::size_t rebuilds_ = 0;
};

}  // namespace sheardiff
