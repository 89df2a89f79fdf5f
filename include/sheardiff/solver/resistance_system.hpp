#pragma once
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sheardiff/core/particles.hpp"
#include "sheardiff/interactions/system_entries.hpp"
#include "sheardiff/neighbour/neighbour_list.hpp"
#include "sheardiff/solver/sparse_cholesky.hpp"

namespace sheardiff {

// The per-step force/torque balance A U + b V = g of the mobile particles (docs/model.md
// section 6), with A = drag + sum of pair blocks (+ dt K for implicit springs) symmetric
// positive definite.
// Unknowns: `dof` per mobile particle, the first dof components of its generalised velocity
// (discs: 3 = u_x, u_y, omega; 2 = no rotation; spheres: 6 = u, omega; 3 = no rotation), plus the
// optional y velocity V of one floating wall, eliminated by two back-solves on one factor.
// The sparsity pattern (and the symbolic factorisation) are rebuilt only with the neighbour
// list: pairs out of range keep their structural zeros.
class ResistanceSystem final : public SystemEntries {
 public:
  // dimension: of the packing (2 discs, 3 spheres), for the factorisation's tuning.
  explicit ResistanceSystem(int dof = 3, const std::string& cholesky = "cholmod", int dimension = 2)
      : dof_(dof), llt_(make_sparse_cholesky(cholesky, dimension)) {}

  int dof() const { return dof_; }
  std::size_t unknowns() const { return static_cast<std::size_t>(dof_) * n_ + extra_; }
  // The first unknown after the particles' (extra unknowns, e.g. a fluid layer's, follow).
  std::size_t particle_unknowns() const { return static_cast<std::size_t>(dof_) * n_; }

  // New pattern from the neighbour list. diagonal_only: no pair ever couples two particles
  // (no lubrication, explicit springs), so A is diagonal and no factorisation is needed.
  // extra_unknowns follow the particles' with the entries extra_entries (row >= col, global
  // indices) in the pattern: the blocks of a fluid layer.
  template <class D>
  void set_pattern(std::size_t n_mobile, const std::vector<PairOf<D>>& pairs,
                   const ParticlesOf<D>& p, bool diagonal_only, std::size_t extra_unknowns = 0,
                   const std::vector<std::pair<int, int>>& extra_entries = {});

  void clear();
  // One-body terms: resistance on the diagonal and force on the right-hand side.
  // (Vec3 for a disc, Vec6 for a sphere: its first dof components are unknowns.)
  void add_self(int i, const Vec3& resistance, const Vec3& force) {
    add_self_of(i, resistance, force);
  }
  void add_self(int i, const Vec6& resistance, const Vec6& force) {
    add_self_of(i, resistance, force);
  }
  // Pair k of the list: generalised pair force -M U_pair + f, with U_pair = (U_i, U_j + known_j).
  // j_floating: j belongs to the floating wall, whose y velocity is the extra unknown V.
  // (Mat6, Vec6, Vec3 for two discs; Mat12, Vec12, Vec6 for two spheres.)
  template <class PairType, class Matrix, class Vector, class Body>
  void add_pair(std::size_t k, const PairType& pr, const Matrix& m, const Vector& f,
                const Body& known_j, bool j_mobile, bool j_floating);

  // One entry of the matrix (row >= col, in the pattern) and of the right-hand side.
  void add_value(int row, int col, double v) override;
  void add_rhs(int row, double v) override { g_[row] += v; }

  // Solve. With a floating wall, its y force balance reads b.U + c V = wall_rhs - load.
  // Returns false if the factorisation failed (matrix not positive definite).
  bool solve(VecX& u);
  // capped: set when |V| hit free_fall_cap (the load is then not balanced).
  bool solve_with_floating_wall(VecX& u, double load, double free_fall_cap, double& v,
                                bool& capped);

  // Solve A u = g + m e with the constraint e . u = 0 for the multiplier m (a pressure gradient
  // holding a flux): two back-solves on one factor.
  bool solve_with_multiplier(VecX& u, const VecX& e, double& m);

  // After a solve: the matrix becomes A + k w w^T (w over the unknowns) and the right-hand side
  // g + dg, solved next time with the factor of A by the Woodbury identity (one back-solve per
  // added term instead of a new factorisation). clear() drops the terms. A term that also
  // reaches the floating wall's y velocity (component w_wall) changes the wall's border instead
  // of A there: b += k w_wall w, c += k w_wall^2, and its right-hand side by wall_rhs_change
  // (the border stays outside the factor; A^-1 b follows from the term's column of A^-1 W, which
  // the Woodbury solve computes anyway, so such a term costs no more than any other).
  void add_low_rank(const VecX& w, double k, const VecX& dg, double w_wall = 0.0,
                    double wall_rhs_change = 0.0);
  // Whether `more` terms on top of the pending ones are cheaper than a new factorisation,
  // counting one back-substitution a term (its column of A^-1 W is kept between solves). A
  // pass solves its terms' columns as one block, which costs less (3-6x for spheres): the
  // budget errs towards refactorising, and a larger one for spheres was not faster in runs
  // (docs/performance.md "Spheres").
  bool low_rank_pays(std::size_t more) const;
  void set_max_low_rank_terms(std::size_t n) { max_low_rank_terms_ = n; }
  std::size_t low_rank_solves() const { return low_rank_solves_; }
  std::size_t low_rank_terms() const { return low_rank_terms_; }

  // Diagnostics: relative residual |A U + b V - g - m e| / |g + m e| of the last solve.
  double residual(const VecX& u, double v) const;
  // The factorised A. After low-rank passes it lacks their pending terms k w w^T, while rhs()
  // and the wall's border below include their changes: the system solved is then matrix() plus
  // the terms (what residual() checks).
  const Eigen::SparseMatrix<double>& matrix() const { return a_; }
  const VecX& rhs() const { return g_; }
  // The floating wall's border of the system: column b, diagonal c and right-hand side
  // (before the load is subtracted).
  const VecX& wall_column() const { return b_; }
  double wall_diagonal() const { return c_; }
  double wall_rhs() const { return wall_rhs_; }
  std::size_t factorisations() const { return factorisations_; }
  std::size_t analyses() const { return analyses_; }
  // The work counters, for checkpoints: a resumed run's summary reports the whole run's.
  void serialize_counters(Archive& a) {
    a.io(factorisations_), a.io(analyses_), a.io(low_rank_solves_), a.io(low_rank_terms_);
  }

 private:
  int index(int row, int col) const;
  template <class Body>
  void add_self_of(int i, const Body& resistance, const Body& force);

  int dof_;
  std::size_t n_ = 0, extra_ = 0;
  bool diagonal_only_ = false;
  Eigen::SparseMatrix<double> a_;  // lower triangle
  VecX g_, b_;
  double c_ = 0.0, wall_rhs_ = 0.0;
  VecX mult_e_;  // the multiplier's direction and value of the last solve_with_multiplier
  double mult_ = 0.0;
  std::vector<int> diag_idx_;  // dof*dof entries per particle (-1 above the diagonal)
  std::vector<int> pair_idx_;  // dof*dof entries per listed pair, -1 for non mobile-mobile
  std::vector<double> diag_;   // diagonal_only storage
  // Factorise A unless the factor is already A's (low-rank terms pending), then A'^-1 x.
  bool prepare();
  // a_inverse_x: A^-1 x of the current factor if already solved (non-empty), else filled.
  VecX apply_inverse(const VecX& x, VecX* a_inverse_x = nullptr);
  VecX a_inverse_b_;  // A^-1 b of the current factor; empty until solved
  // Changes of b by low-rank terms since A^-1 b was solved: b += coef * w of term `index`, so
  // A^-1 b += coef * lr_z_.col(index) once the Woodbury columns are there.
  std::vector<std::pair<Eigen::Index, double>> a_inverse_b_updates_;

  std::unique_ptr<SparseCholesky> llt_;
  std::size_t factorisations_ = 0, analyses_ = 0, low_rank_solves_ = 0, low_rank_terms_ = 0;
  bool factor_of_a_ = false;  // llt_ holds the factor of the current a_
  // Low-rank terms k w w^T added since the factorisation; w has a few non-zeros (a pair's
  // unknowns), kept as (index, value).
  struct LowRankTerm {
    std::vector<std::pair<Eigen::Index, double>> w;
    double k;
  };
  std::vector<LowRankTerm> lr_;
  std::size_t max_low_rank_terms_ = 0;
  double dot(const LowRankTerm& t, const VecX& x) const;
  Eigen::Index lr_z_cols_ = 0;  // columns of lr_z_ computed (A^-1 w of the first terms)
  Eigen::MatrixXd lr_z_;        // A^-1 W, and the LDLT of diag(1/k) + W^T A^-1 W
  // optional: a default-constructed Eigen::LDLT leaves its info flag uninitialised, and moving
  // the system (Simulation set-up) would read it (UBSan: invalid enum load).
  std::optional<Eigen::LDLT<Eigen::MatrixXd>> lr_s_;
  bool lr_ready_ = false;
};

}  // namespace sheardiff
