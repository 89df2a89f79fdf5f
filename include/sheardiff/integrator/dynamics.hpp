#pragma once
#include <array>
#include <optional>
#include <vector>

#include "sheardiff/core/archive.hpp"
#include "sheardiff/core/box.hpp"
#include "sheardiff/core/imposed_flow.hpp"
#include "sheardiff/core/particles.hpp"
#include "sheardiff/core/walls.hpp"
#include "sheardiff/neighbour/neighbour_list.hpp"
#include "sheardiff/solver/force_balance.hpp"

namespace sheardiff {

// Limits on one step (docs/model.md section 7). fixed_dt > 0 switches the adaptive choice off.
struct StepLimits {
  // Every limit is set from the configuration (engine.cpp), whose schema holds the defaults and
  // the allowed ranges; none is a default of its own here.
  double fixed_dt = 0.0;
  double max_displacement = 0.0;  // non-affine, d
  double max_gap_fraction = 0.0;  // of (gap + delta s / 2)
  double max_overlap_change = 0.0;
  // Largest overlap a closing pair may reach in the step it touches (0 = none): the gap limit
  // alone lets it reach max_gap_fraction x delta s / 2.
  double max_entry_overlap = 0.0;
  double max_strain_step = 0.0;
  double explicit_dt = 0.0;  // stability cap of explicit springs (0 = none)
  double end_time = 0.0;     // a fixed dt is shortened to land on it (0 = none)
};

// Which limit set a step (reported as fractions of steps in summary.json).
enum class StepLimit : int { Fixed, Strain, Displacement, Gap, Overlap, Explicit, Growth, Count };
const char* to_string(StepLimit l);

// The state of a run and the operations an integrator composes: solve for velocities at the
// current configuration, pick a step, move everything by a step. No policy lives here. Discs
// (D = Dim2) or spheres (Dim3).
template <class D>
class DynamicsOf {
 public:
  using Point = typename D::Point;
  using Particles = ParticlesOf<D>;
  using Box = BoxOf<D>;
  using Pair = PairOf<D>;
  using NeighbourList = NeighbourListOf<D>;
  using ForceBalance = ForceBalanceOf<D>;
  using Velocities = VelocitiesOf<D>;

  DynamicsOf(Particles particles, Box box, ImposedFlow flow, ForceBalance force_balance,
             NeighbourList neighbours, StepLimits limits, std::optional<WallBodies> walls);

  // Opens/closes contacts at the current configuration; call once at the start of a step.
  void begin_step();
  // Velocities at the current configuration; dt_implicit > 0 for implicit springs.
  bool solve(double dt_implicit, Velocities& v);
  // Implicit springs: a contact that entered the step of length dt sliding (its Coulomb force
  // carried explicitly, no tangential stiffness) but whose solved slip v releases its spring
  // (contact.stick_rule) is not sliding in this step: it is marked sticking so that a re-solve
  // gives it its tangential stiffness. Returns how many contacts changed (0: the sliding set is
  // consistent with v). switched (optional): the indices of those contacts in
  // neighbours().pairs().
  int stick_reversed_sliding(const Velocities& v, double dt,
                             std::vector<std::size_t>* switched = nullptr);
  // Solve again after stick_reversed_sliding at the same positions and dt: the new tangential
  // stiffness enters as low-rank terms on the last factor (ForceBalance::resolve_with_sticking).
  bool resolve_with_sticking(double dt_implicit, const std::vector<std::size_t>& switched,
                             Velocities& v);
  // Largest step the limits allow for these velocities (fixed_dt if set); *which says which.
  double dt_limit(const Velocities& v, StepLimit* which = nullptr) const;
  // fixed_dt, shortened on the last step so that a run ends exactly at limits().end_time.
  double fixed_step() const;
  // A step chosen by the limits, shortened to end exactly at the landing clock (a strain) if it
  // would reach or pass it: the run's next frame, so that frames are evenly spaced. A step that
  // ends short of it is left as it is; none is set (0) by default, and never with a fixed dt.
  void set_landing(double clock) { landing_ = clock; }
  double landed(double dt) const;
  // Integrators report the limit that set each step they take.
  void count_step_limit(StepLimit l) { ++limit_counts_[static_cast<int>(l)]; }
  const std::array<long, static_cast<int>(StepLimit::Count)>& step_limit_counts() const {
    return limit_counts_;
  }
  // Move particles, walls and the Lees-Edwards offset by dt with velocities v; stretch the
  // tangential springs with the slip of v; when the skin is used up the neighbour list is
  // rebuilt at the next begin_step() (never after a predictor move, allow_rebuild = false,
  // that restore() will undo).
  void advance(double dt, const Velocities& v, bool allow_rebuild = true);
  void finish_step() { ++steps_; }

  // Everything that evolves (for checkpoints); loading re-derives the matrix pattern.
  // layout5: the state holds the particles' image counts and the heights the fluid layer's
  // pattern was built from (checkpoint layout 5 on). Without them the images are estimated
  // from the unwrapped positions, and a channel run resumes, but not bit-identically.
  void serialize(Archive& a, bool layout5 = true);

  struct Saved {
    std::vector<Point> position, unwrapped;
    std::vector<typename D::Images> image;
    std::vector<PairHistoryOf<D>> contacts;
    Box box;
    double time;
  };
  Saved save() const;
  // Image counts from the unwrapped positions (for a checkpoint that has none).
  void estimate_images();
  // Undo moves made since save() with allow_rebuild = false.
  void restore(const Saved& s);

  const Particles& particles() const { return particles_; }
  // Mutable access for set-up and tests (e.g. external forces); positions changed here take
  // effect at the next rebuild, so call rebuild_now() after moving particles.
  Particles& particles_mut() { return particles_; }
  void rebuild_now() {
    rebuild();
    rebuild_due_ = false;
  }
  const Box& box() const { return box_; }
  const ImposedFlow& flow() const { return flow_; }
  const NeighbourList& neighbours() const { return neighbours_; }
  const ForceBalance& force_balance() const { return force_balance_; }
  ForceBalance& force_balance() { return force_balance_; }
  const StepLimits& limits() const { return limits_; }
  const std::optional<WallBodies>& walls() const { return walls_; }
  double time() const { return time_; }
  // The run's clock (strain gammadot t for a shear).
  double strain() const { return flow_.clock(time_); }
  long steps() const { return steps_; }
  // Gap between the walls (mean y of top minus bottom wall particles), or Ly.
  double height() const;
  const WallBodies* wall_bodies() const { return walls_ ? &*walls_ : nullptr; }

 private:
  void rebuild();

  Particles particles_;
  Box box_;
  ImposedFlow flow_;
  ForceBalance force_balance_;
  NeighbourList neighbours_;
  StepLimits limits_;
  std::optional<WallBodies> walls_;
  double time_ = 0.0;
  double landing_ = 0.0;  // on the run's clock; not part of the state (the step loop sets it)
  long steps_ = 0;
  bool rebuild_due_ = false;
  std::array<long, static_cast<int>(StepLimit::Count)> limit_counts_{};
  std::vector<Point> na_;  // scratch: non-affine displacement of the last step
};

using Dynamics = DynamicsOf<Dim2>;
using Dynamics3 = DynamicsOf<Dim3>;

}  // namespace sheardiff
