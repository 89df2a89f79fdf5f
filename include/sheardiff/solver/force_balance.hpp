#pragma once
#include <optional>
#include <vector>

#include "sheardiff/core/box.hpp"
#include "sheardiff/core/particles.hpp"
#include "sheardiff/interactions/contact.hpp"
#include "sheardiff/interactions/lubrication.hpp"
#include "sheardiff/interactions/stokes_drag.hpp"
#include "sheardiff/neighbour/neighbour_list.hpp"
#include "sheardiff/solver/resistance_system.hpp"

namespace sheardiff {

// The rigid top wall: x velocity imposed, y velocity solved so that the suspension pushes on it
// with exactly `load` = P Lx lz (docs/model.md section 6).
struct WallDrive {
  double vx = 0.0;
  double load = 0.0;
  double free_fall_cap = 1.0;  // |V| bound while nothing (or almost nothing) holds the wall
};

// What one pair contributes this step: its geometry, its matrix block M (resistance, plus
// dt K for implicit springs) and its spring force f; the pair's generalised force is
// -M U_pair + f with U_pair = (U_i, U_j + image_j), U_j the velocity of particle j itself and
// image_j the extra velocity of its Lees-Edwards image.
struct PairTerm {
  PairGeometry g;
  Mat6 m = Mat6::Zero();
  Vec6 f = Vec6::Zero();
  Vec3 image_j = Vec3::Zero();
  bool on = false;       // inside the lubrication range or in contact
  bool sliding = false;  // contact at its Coulomb limit at the start of the step

  Vec6 force(const Vec3& ui, const Vec3& uj) const {
    Vec6 u;
    u << ui, uj + image_j;
    return f - m * u;
  }
};

struct Velocities {
  std::vector<Vec3> u;          // every particle: mobile solved, wall particles their body's motion
  double wall_v = 0.0;          // y velocity of the floating wall
  bool wall_free_fall = false;  // V was capped: the wall is not (yet) held by the packing
};

// Pair laws + drag -> the linear system -> velocities. One loop over the listed pairs serves
// every pair law; absent laws (no lubrication, frictionless) cost nothing inside it.
class ForceBalance {
 public:
  // implicit_springs: the integrator will pass dt_implicit > 0, so contacts couple particles
  // in the matrix even without lubrication.
  ForceBalance(std::optional<Lubrication> lubrication, FrictionalContact contact, int dof,
               bool implicit_springs, const std::string& cholesky = "cholmod");

  // The neighbour list changed: new sparsity pattern and symbolic analysis.
  void on_rebuild(const Particles& p, const std::vector<Pair>& pairs);
  // Open/close contacts from the current geometry (a new contact starts with xi = 0).
  static void update_contacts(const Particles& p, const Box& box, std::vector<Pair>& pairs);

  // Assemble at the current positions and solve. dt_implicit > 0 treats the springs linearly
  // implicitly over a step of that length. wall = nullptr when there is no floating wall.
  bool solve(const Particles& p, const Box& box, const ShearFlow& flow,
             const std::vector<Pair>& pairs, double dt_implicit, const WallDrive* wall,
             Velocities& out);
  // Implicit springs: the contacts `switched` (indices into pairs) have just been marked
  // sticking after a solve at the same positions and dt_implicit; solves again with their
  // tangential stiffness added as low-rank terms to the factor of the last solve (no new
  // assembly or factorisation; a full solve() if one of them touches the floating wall).
  bool resolve_with_sticking(const Particles& p, const Box& box, const ShearFlow& flow,
                             const std::vector<Pair>& pairs,
                             const std::vector<std::size_t>& switched, double dt_implicit,
                             const WallDrive* wall, Velocities& out);
  // The two halves of solve(), separately for benchmarks: pair terms and matrix, then the
  // factorisation and back-substitution.
  void assemble(const Particles& p, const Box& box, const ShearFlow& flow,
                const std::vector<Pair>& pairs, double dt_implicit, const WallDrive* wall);
  bool solve_assembled(const Particles& p, const ShearFlow& flow, const WallDrive* wall,
                       Velocities& out);

  const std::vector<PairTerm>& terms() const { return terms_; }
  const ResistanceSystem& system() const { return system_; }
  ResistanceSystem& system() { return system_; }
  // Most low-rank terms per factorisation before a re-solve refactorises (0: from the
  // factorisation's flop count, the default).
  void set_max_low_rank_terms(std::size_t n) { system_.set_max_low_rank_terms(n); }
  const std::optional<Lubrication>& lubrication() const { return lubrication_; }
  const FrictionalContact& contact() const { return contact_; }
  // |A U + b V - g| / |g| of the last solve.
  double last_residual() const { return residual_; }
  void set_check_residual(bool on) { check_residual_ = on; }

 private:
  template <bool kWalls>
  void assemble_pairs(const Particles& p, const Box& box, const std::vector<Pair>& pairs,
                      double dt_implicit, const WallDrive* wall);

  std::optional<Lubrication> lubrication_;
  FrictionalContact contact_;
  ResistanceSystem system_;
  bool diagonal_only_;
  std::vector<PairTerm> terms_;
  VecX u_;
  double residual_ = 0.0;
  bool check_residual_ = false;
};

}  // namespace sheardiff
