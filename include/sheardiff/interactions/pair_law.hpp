#pragma once
// The contract every pair law meets (docs/model.md section 4), in the spirit of HOOMD-blue's
// evaluators: a law is a small struct, and the generic pair loop (PairLaws, ForceBalance) is
// instantiated for the list of laws in pair_laws.hpp, so no call in the per-pair loop is virtual.
//
// A law L provides
//   using History = ...;           its per-contact state (NoHistory when it keeps none);
//   static std::optional<L> from(const Config&);   the law of a run, or none when it is off;
//   double range_factor() const;   largest centre distance over (a_i + a_j) at which it acts,
//                                  for the smallest pair (a_i + a_j = d): sizes the neighbour list;
//   bool acts(const PairGeometry&, bool touching) const;   whether it acts on the pair now
//                                  (touching: the pair was in contact at the start of the step);
//   void add_block(const PairGeometry&, const History&, bool touching, double dt_implicit,
//                  PairBlock&) const;   its resistance block and force on a pair it acts on;
//                                  dt_implicit > 0: its stiffness is treated linearly implicitly;
//   bool resistive() const;        whether it adds a matrix block even with explicit springs;
//   bool keeps_history() const;    whether advance/cap below do anything;
//   void advance(History&, const PairGeometry&, const Vec6& u, double dt) const;   the history
//                                  over a step, at the geometry of its start, pair velocity u;
//   void cap(History&, const PairGeometry&) const;   the history's limit at the end of the step;
//   void add_stability(double a, StabilityTerms&) const;   its stiffness and damping on the
//                                  smallest pair (radius a) for the explicit stability limit
//                                  (PairLaws::explicit_stability_dt adds the shared drag);
//   bool needs_rotations() const;  whether it couples rotation to translation.
// Every operation that takes a PairGeometry also takes a PairGeometry3 (two spheres), with
// PairBlock3, a pair velocity Vec12 and its history in three dimensions (a law that keeps one
// names it History3), as a template or an overload: the engine is instantiated for both.
#include "sheardiff/interactions/pair_geometry.hpp"

namespace sheardiff {

// The history of a law that keeps none.
struct NoHistory {};

// Where laws write one pair's matrix block M and force f (the pair's generalised force is
// -M U_pair + f). The first law to write a part assigns it, later ones add to it, so that a
// single law gives exactly its own block (bit for bit, not 0 + block). M is 6x6 for two discs,
// 12x12 for two spheres.
template <class Matrix, class Vector>
struct PairBlockOf {
  Matrix& m;
  Vector& f;
  bool& sliding;  // a contact at its Coulomb limit (no tangential stiffness this step)
  bool m_set = false, f_set = false;

  template <class E>
  void add_matrix(const E& x) {
    if (m_set) {
      m += x;
    } else {
      m = x;
      m_set = true;
    }
  }
  template <class E>
  void add_force(const E& x) {
    if (f_set) {
      f += x;
    } else {
      f = x;
      f_set = true;
    }
  }
};

using PairBlock = PairBlockOf<Mat6, Vec6>;
using PairBlock3 = PairBlockOf<Mat12, Vec12>;

// What sets the explicit stability limit 2 R / k: the normal and tangential stiffness of the
// smallest pair's laws and their damping at contact (plus its drag, shared among the contacts of
// the densest packing).
struct StabilityTerms {
  double normal_damping = 0.0, tangential_damping = 0.0;
  double normal_stiffness = 0.0, tangential_stiffness = 0.0;
};

// Normal direction in pair space (u_x, u_y, omega)_i, (u_x, u_y, omega)_j: the overlap grows at
// normal_mode . U, and a central repulsion F on the pair is -F normal_mode.
inline Vec6 normal_mode(const PairGeometry& g) {
  Vec6 m;
  m << g.n, 0.0, -g.n, 0.0;
  return m;
}
// The same for two spheres, (u, omega)_i, (u, omega)_j.
inline Vec12 normal_mode(const PairGeometry3& g) {
  Vec12 m = Vec12::Zero();
  m.segment<3>(0) = g.n;
  m.segment<3>(6) = -g.n;
  return m;
}

}  // namespace sheardiff
