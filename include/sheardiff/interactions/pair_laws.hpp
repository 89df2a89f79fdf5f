#pragma once
// The pair laws of the engine and the generic operations over them (pair_law.hpp has the
// contract). A new law is its header and its parameters header (NAME_params.hpp: its keys,
// declared once), one member of Config, one declare_section line and one entry in PairLaws below
// (and, if it keeps a per-contact history, one member of PairHistory, core/pair_history.hpp).
#include <algorithm>
#include <optional>
#include <tuple>
#include <type_traits>

#include "sheardiff/config.hpp"
#include "sheardiff/core/pair_history.hpp"
#include "sheardiff/interactions/contact.hpp"
#include "sheardiff/interactions/lubrication.hpp"
#include "sheardiff/interactions/pair_law.hpp"
#include "sheardiff/interactions/repulsion.hpp"

namespace sheardiff {

// The history of law L inside a pair's record (PairHistory, or PairHistory3 between spheres).
template <class L, class Record>
decltype(auto) history_of(Record& h) {
  if constexpr (std::is_same_v<typename L::History, TangentialSpring>)
    return (h.contact);
  else
    return typename L::History{};
}

// The laws of one run, each present or not; every loop over them is unrolled at compile time.
template <class... Laws>
class PairLawSet {
 public:
  PairLawSet() = default;
  explicit PairLawSet(std::optional<Laws>... laws) : laws_(std::move(laws)...) {}
  static PairLawSet from(const Config& cfg) { return PairLawSet(Laws::from(cfg)...); }

  template <class L>
  const std::optional<L>& get() const {
    return std::get<std::optional<L>>(laws_);
  }
  template <class L>
  std::optional<L>& get() {
    return std::get<std::optional<L>>(laws_);
  }
  // f(law) for every present law, in the order of the list.
  template <class F>
  void for_each(F&& f) const {
    std::apply([&](const auto&... law) { ((law ? f(*law) : void()), ...); }, laws_);
  }
  template <class F>
  bool any(F&& f) const {
    bool r = false;
    for_each([&](const auto& law) { r = r || f(law); });
    return r;
  }

  // Largest pair range over (a_i + a_j): the neighbour list's cut-off without its skin.
  double range_factor() const {
    double r = 1.0;
    for_each([&](const auto& law) { r = std::max(r, law.range_factor()); });
    return r;
  }
  bool needs_rotations() const {
    return any([](const auto& law) { return law.needs_rotations(); });
  }
  bool resistive() const {
    return any([](const auto& law) { return law.resistive(); });
  }
  bool keeps_history() const {
    return any([](const auto& law) { return law.keeps_history(); });
  }
  // Stability limit of explicit springs (docs/model.md section 7): 2 min(R / k) over the normal
  // and slip modes of the smallest pair (two small particles), R its laws' damping at contact
  // plus the drag of the pair's relative motion shared among kDragSharers[dimension] contacts.
  // A packing's fastest mode is not a lone pair's: in the densest lattice of small particles
  // each one's drag is shared among all its contacts (and the spins soften the slip mode), so a
  // mode whose damping is drag-bound relaxes up to 8 times faster than a pair's. The shares
  // (5 discs, 9 spheres) are a little above the exact 4.5 and 8 of the periodic triangular and
  // FCC lattices (kt = kn, no lubrication); tests/unit/test_explicit_stability.cpp checks the
  // limit against the lattices' eigenvalues for every law mix (lambda dt_stab 0.89-1.97).
  static constexpr double kDragSharers2d = 5.0, kDragSharers3d = 9.0;
  double explicit_stability_dt(int dimension) const {
    const double a = 0.5;
    const double drag =
        3.0 * kPi * 2.0 * a / 2.0 / (dimension == 3 ? kDragSharers3d : kDragSharers2d);
    StabilityTerms s;
    s.normal_damping = s.tangential_damping = drag;
    for_each([&](const auto& law) { law.add_stability(a, s); });
    double dt = 2.0 * s.normal_damping / s.normal_stiffness;
    if (s.tangential_stiffness > 0.0)
      dt = std::min(dt, 2.0 * s.tangential_damping / s.tangential_stiffness);
    return dt;
  }

  // The block and force of one pair from every law acting on it; false if none acts (then m
  // and f are left as they were). Two discs (PairGeometry, PairHistory, Mat6, Vec6) or two
  // spheres (PairGeometry3, PairHistory3, Mat12, Vec12).
  template <class Geometry, class Record, class Matrix, class Vector>
  bool add_blocks(const Geometry& g, const Record& h, double dt_implicit, Matrix& m, Vector& f,
                  bool& sliding) const {
    bool on = false;
    PairBlockOf<Matrix, Vector> b{m, f, sliding};
    for_each([&](const auto& law) {
      using L = std::decay_t<decltype(law)>;
      if (!law.acts(g, h.touching)) return;
      if (!on) {
        m.setZero();
        f.setZero();
        sliding = false;
        on = true;
      }
      law.add_block(g, history_of<L>(h), h.touching, dt_implicit, b);
    });
    return on;
  }
  // The histories of a touching pair over a step (geometry of its start, pair velocity u) ...
  template <class Record, class Geometry, class PairVelocity>
  void advance(Record& h, const Geometry& g, const PairVelocity& u, double dt) const {
    for_each([&](const auto& law) {
      using L = std::decay_t<decltype(law)>;
      if constexpr (!std::is_same_v<typename L::History, NoHistory>)
        if (law.keeps_history()) law.advance(history_of<L>(h), g, u, dt);
    });
  }
  // ... and capped at its end.
  template <class Record, class Geometry>
  void cap(Record& h, const Geometry& g) const {
    for_each([&](const auto& law) {
      using L = std::decay_t<decltype(law)>;
      if constexpr (!std::is_same_v<typename L::History, NoHistory>)
        if (law.keeps_history()) law.cap(history_of<L>(h), g);
    });
  }

 private:
  std::tuple<std::optional<Laws>...> laws_;
};

// The engine's pair laws, in the order their blocks are added.
using PairLaws = PairLawSet<Lubrication, FrictionalContact, DoubleLayerRepulsion>;

}  // namespace sheardiff
