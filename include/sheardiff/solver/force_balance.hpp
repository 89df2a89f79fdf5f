#pragma once
#include <optional>
#include <vector>

#include "sheardiff/core/box.hpp"
#include "sheardiff/core/imposed_flow.hpp"
#include "sheardiff/core/particles.hpp"
#include "sheardiff/core/walls.hpp"
#include "sheardiff/interactions/fluid_layer.hpp"
#include "sheardiff/interactions/pair_laws.hpp"
#include "sheardiff/interactions/stokes_drag.hpp"
#include "sheardiff/neighbour/neighbour_list.hpp"
#include "sheardiff/solver/resistance_system.hpp"

namespace sheardiff {

// What one pair contributes this step: its geometry, its matrix block M (resistance, plus
// dt K for implicit springs) and its spring force f; the pair's generalised force is
// -M U_pair + f with U_pair = (U_i, U_j + image_j), U_j the velocity of particle j itself and
// image_j the extra velocity of its Lees-Edwards image.
template <class D>
struct PairTermOf {
  using Body = typename D::Body;
  using PairVector = typename D::PairVector;
  using PairMatrix = typename D::PairMatrix;
  PairGeometryOf<D> g;
  PairMatrix m = PairMatrix::Zero();
  PairVector f = PairVector::Zero();
  Body image_j = Body::Zero();
  bool on = false;       // some pair law acts on the pair
  bool sliding = false;  // contact at its Coulomb limit at the start of the step

  PairVector force(const Body& ui, const Body& uj) const {
    PairVector u;
    u << ui, uj + image_j;
    return f - m * u;
  }
};
using PairTerm = PairTermOf<Dim2>;

template <class D>
struct VelocitiesOf {
  // every particle: mobile solved, wall particles their body's motion
  std::vector<typename D::Body> u;
  double wall_v = 0.0;          // y velocity of the floating wall
  bool wall_free_fall = false;  // V was capped: the wall is not (yet) held by the packing
  // With a fluid layer: its deviation from the reference flow at the interior nodes, and the
  // pressure gradient G = -dp/dx that holds the mean fluid velocity (eta <u> / d^2 units).
  std::vector<double> fluid;
  double pressure_gradient = 0.0;
};
using Velocities = VelocitiesOf<Dim2>;

// Pair laws + drag -> the linear system -> velocities. One loop over the listed pairs serves
// every pair law (PairLaws, unrolled at compile time); absent laws cost nothing inside it. The
// per-pair histories the laws keep are advanced and capped here too. Discs (D = Dim2) or spheres
// (Dim3); the fluid layer of a channel is a disc scene's only.
template <class D>
class ForceBalanceOf {
 public:
  using Point = typename D::Point;
  using Body = typename D::Body;
  using Particles = ParticlesOf<D>;
  using Box = BoxOf<D>;
  using Pair = PairOf<D>;
  using PairTerm = PairTermOf<D>;
  using Velocities = VelocitiesOf<D>;

  // implicit_springs: the integrator will pass dt_implicit > 0, so contacts couple particles
  // in the matrix even without lubrication.
  ForceBalanceOf(PairLaws laws, int dof, bool implicit_springs,
                 const std::string& cholesky = "cholmod");
  // Lubrication (or none) and contacts, no other law.
  ForceBalanceOf(std::optional<Lubrication> lubrication, FrictionalContact contact, int dof,
                 bool implicit_springs, const std::string& cholesky = "cholmod")
      : ForceBalanceOf(PairLaws(lubrication, contact, std::nullopt), dof, implicit_springs,
                       cholesky) {}

  // The fluid of a channel as further unknowns (interactions/fluid_layer.hpp); set before the
  // first on_rebuild.
  void set_fluid(FluidLayer fluid) { fluid_ = std::move(fluid); }
  const std::optional<FluidLayer>& fluid() const { return fluid_; }
  // The fluid's velocity (v, omega) at x: the imposed flow plus the layer's deviation.
  Body fluid_velocity(const ImposedFlow& flow, const Velocities& v, const Point& x) const {
    Body u = flow.velocity(x);
    if constexpr (D::space == 2) {
      if (fluid_) {
        u.x() += fluid_->deviation(v.fluid, x.y());
        u.z() -= 0.5 * fluid_->deviation_slope(v.fluid, x.y());
      }
    }
    return u;
  }
  // The largest |dv_x/dy| of that fluid.
  double max_shear_rate(const ImposedFlow& flow, const Velocities& v) const {
    return fluid_ ? flow.max_shear_rate() + fluid_->max_deviation_slope(v.fluid)
                  : flow.max_shear_rate();
  }

  // The neighbour list changed: new sparsity pattern and symbolic analysis. With a fluid layer
  // the pattern depends on the particles' heights at the rebuild, kept for checkpoints; a
  // restored run passes restored = true to build it from those (checkpoint layout 5) rather
  // than from the positions at the checkpoint, so that its solves are bit-identical.
  void on_rebuild(const Particles& p, const std::vector<Pair>& pairs, bool restored = false);
  void serialize_fluid_pattern(Archive& a) {
    if (fluid_) a.io(pattern_y_);
  }
  // Open/close contacts from the current geometry (a new contact starts with a fresh history).
  static void update_contacts(const Particles& p, const Box& box, std::vector<Pair>& pairs);
  // The laws' per-pair histories over a step of length dt with velocities u, at the positions
  // of its start (call before the move) ...
  void advance_histories(const Particles& p, const Box& box, const ImposedFlow& flow,
                         std::vector<Pair>& pairs, const std::vector<Body>& u, double dt) const;
  // ... and their caps at its end (after the move).
  void cap_histories(const Particles& p, const Box& box, std::vector<Pair>& pairs) const;
  // Implicit springs: contacts that entered the step (of length dt) sliding and whose solved
  // slip u releases their spring stick (FrictionalContact::stick_after_slip, by the contact's
  // stick rule); returns how many changed and their indices into pairs in *switched (optional).
  int stick_reversed_sliding(const Particles& p, std::vector<Pair>& pairs,
                             const std::vector<Body>& u, double dt,
                             std::vector<std::size_t>* switched) const;

  // Assemble at the current positions and solve. dt_implicit > 0 treats the springs linearly
  // implicitly over a step of that length. walls = nullptr when the scene has none; a floating
  // top wall's y velocity is solved so that the suspension pushes on it with exactly its load
  // (docs/model.md section 6).
  bool solve(const Particles& p, const Box& box, const ImposedFlow& flow,
             const std::vector<Pair>& pairs, double dt_implicit, const WallBodies* walls,
             Velocities& out);
  // Implicit springs: the contacts `switched` (indices into pairs) have just been marked
  // sticking after a solve at the same positions and dt_implicit; solves again with their
  // tangential stiffness added as low-rank terms to the factor of the last solve (no new
  // assembly or factorisation; a full solve() when they would cost more than one).
  bool resolve_with_sticking(const Particles& p, const Box& box, const ImposedFlow& flow,
                             const std::vector<Pair>& pairs,
                             const std::vector<std::size_t>& switched, double dt_implicit,
                             const WallBodies* walls, Velocities& out);
  // The two halves of solve(), separately for benchmarks: pair terms and matrix, then the
  // factorisation and back-substitution.
  void assemble(const Particles& p, const Box& box, const ImposedFlow& flow,
                const std::vector<Pair>& pairs, double dt_implicit, const WallBodies* walls);
  bool solve_assembled(const Particles& p, const ImposedFlow& flow, const WallBodies* walls,
                       Velocities& out);

  const std::vector<PairTerm>& terms() const { return terms_; }
  const ResistanceSystem& system() const { return system_; }
  ResistanceSystem& system() { return system_; }
  // Most low-rank terms per factorisation before a re-solve refactorises (0: from the
  // factorisation's flop count, the default).
  void set_max_low_rank_terms(std::size_t n) { system_.set_max_low_rank_terms(n); }
  const PairLaws& laws() const { return laws_; }
  const std::optional<Lubrication>& lubrication() const { return laws_.get<Lubrication>(); }
  const FrictionalContact& contact() const { return *laws_.get<FrictionalContact>(); }
  // What the sticking re-solves cost (resolve_with_sticking): passes solved on the old factor
  // with low-rank terms, passes refactorised because their switched contacts would cost more
  // back-substitutions than a factorisation, and the contacts switched in all of them.
  // retired_wall: checkpoint layout 7's count of passes refactorised because a switched contact
  // touched the floating wall (such contacts are low-rank terms now), read and written so that
  // the layout stays, not reported.
  struct StickingCounts {
    long low_rank = 0, refactorised_budget = 0, retired_wall = 0, switched = 0;
  };
  const StickingCounts& sticking_counts() const { return sticking_; }
  // The work counters, for checkpoints (after the system's, as a later layout's addition).
  void serialize_sticking_counts(Archive& a) {
    a.io(sticking_.low_rank), a.io(sticking_.refactorised_budget), a.io(sticking_.retired_wall),
        a.io(sticking_.switched);
  }
  // |A U + b V - g| / |g| of the last solve.
  double last_residual() const { return residual_; }
  void set_check_residual(bool on) { check_residual_ = on; }

 private:
  template <bool kWalls>
  void assemble_pairs(const Particles& p, const Box& box, const ImposedFlow& flow,
                      const std::vector<Pair>& pairs, double dt_implicit, const WallBodies* walls);
  // Implicit springs: the rows w and their shares c of what a sliding contact adds to its
  // tangential stiffness, kt sum c w w^T, when it sticks (one row for two discs; two for two
  // spheres, the one across the stretch short of what the sliding spring already has there,
  // contact.sliding_stiffness).
  struct SlipRow {
    typename D::PairVector w;
    double share = 1.0;
  };
  std::vector<SlipRow> slip_rows(const PairGeometryOf<D>& g, const PairHistoryOf<D>& h) const;

  PairLaws laws_;
  std::optional<FluidLayer> fluid_;
  ResistanceSystem system_;
  bool diagonal_only_;
  std::vector<PairTerm> terms_;
  VecX u_;
  VecX fluid_load_;  // the pressure gradient's generalised force on the fluid unknowns
  std::vector<double> pattern_y_;  // the mobile particles' heights at the last rebuild (fluid)
  double residual_ = 0.0;
  bool check_residual_ = false;
  StickingCounts sticking_;
};

using ForceBalance = ForceBalanceOf<Dim2>;
using ForceBalance3 = ForceBalanceOf<Dim3>;

}  // namespace sheardiff
