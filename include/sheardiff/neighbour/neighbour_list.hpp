#pragma once
#include <cstddef>
#include <type_traits>
#include <vector>

#include "sheardiff/core/archive.hpp"
#include "sheardiff/core/box.hpp"
#include "sheardiff/core/pair_history.hpp"
#include "sheardiff/core/particles.hpp"

namespace sheardiff {

// One listed pair. i is always mobile; j is mobile or a wall particle. j is seen through the
// periodic image (kx, ky[, kz]) of the box. Wall-wall pairs are never listed. history: what the
// pair laws keep for it from step to step (core/pair_history.hpp), carried while the pair
// touches. The 2D record is checkpointed as raw bytes: its layout is fixed.
struct Pair {
  int i = 0, j = 0;
  int kx = 0, ky = 0;
  PairHistory history;
};
struct Pair3 {
  int i = 0, j = 0;
  int kx = 0, ky = 0, kz = 0;
  PairHistory3 history;

  // Field by field: the spring (an Eigen vector) is not trivially copyable.
  void serialize(Archive& a) {
    a.io(i), a.io(j), a.io(kx), a.io(ky), a.io(kz);
    a.io(history.touching), a.io(history.contact.xi), a.io(history.contact.sliding);
    if (a.layout() >= 8) a.io(history.contact.across);  // layout 7: 1, as after a stick
  }
};
template <class D>
using PairOf = std::conditional_t<D::space == 2, Pair, Pair3>;

// The vector from i to (the image of) j of a listed pair, at the current positions and offset.
inline Vec2 pair_separation(const Particles& p, const Box& box, const Pair& pr) {
  return p.position[pr.j] + box.image_shift(pr.kx, pr.ky) - p.position[pr.i];
}
inline Space3 pair_separation(const Particles3& p, const Box3& box, const Pair3& pr) {
  return p.position[pr.j] + box.image_shift(pr.kx, pr.ky, pr.kz) - p.position[pr.i];
}

// Verlet list built with a nanoflann k-d tree over the particles and their periodic
// (and Lees-Edwards shifted) images. Every pair within s (1 + h_max/2) + skin is listed;
// the list stays valid until the non-affine motion plus the affine shear of a pair can
// have used up the skin.
template <class D>
class NeighbourListOf {
 public:
  using Point = typename D::Point;
  using PairType = PairOf<D>;

  NeighbourListOf(double interaction_range_factor, double skin)
      : range_factor_(interaction_range_factor), skin_(skin) {}

  // Wraps positions into the box, rebuilds the list, and carries the history of touching
  // pairs that are still listed.
  void rebuild(ParticlesOf<D>& p, const BoxOf<D>& box);
  // Accumulate the motion since the last rebuild; na = non-affine displacement of each
  // particle in this step, dstrain = gammadot dt.
  void advance(const std::vector<Point>& na_displacement, double dstrain);
  bool needs_rebuild() const;

  const std::vector<PairType>& pairs() const { return pairs_; }
  std::vector<PairType>& pairs() { return pairs_; }
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
  std::vector<PairType> pairs_;
  std::vector<Point> na_since_build_;
  double strain_since_build_ = 0.0;
  double max_cutoff_ = 0.0;
  std::size_t rebuilds_ = 0;
};

using NeighbourList = NeighbourListOf<Dim2>;
using NeighbourList3 = NeighbourListOf<Dim3>;

}  // namespace sheardiff
