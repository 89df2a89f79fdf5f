#include "sheardiff/solver/resistance_system.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sheardiff {

int ResistanceSystem::index(int row, int col) const {
  const int* inner = a_.innerIndexPtr();
  const int* begin = inner + a_.outerIndexPtr()[col];
  const int* end = inner + a_.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  if (it == end || *it != row) throw std::logic_error("ResistanceSystem: entry not in pattern");
  return static_cast<int>(it - inner);
}

template <class D>
void ResistanceSystem::set_pattern(std::size_t n_mobile, const std::vector<PairOf<D>>& pairs,
                                   const ParticlesOf<D>& p, bool diagonal_only,
                                   std::size_t extra_unknowns,
                                   const std::vector<std::pair<int, int>>& extra_entries) {
  n_ = n_mobile;
  extra_ = extra_unknowns;
  if (extra_ > 0 && diagonal_only)
    throw std::logic_error("ResistanceSystem: extra unknowns need the coupled pattern");
  diagonal_only_ = diagonal_only;
  factor_of_a_ = false;
  lr_.clear();
  a_inverse_b_updates_.clear();
  lr_z_cols_ = 0;
  lr_ready_ = false;
  const int d = dof_;
  const auto nu = static_cast<Eigen::Index>(unknowns());
  g_.setZero(nu);
  b_.setZero(nu);
  if (diagonal_only_) {
    diag_.assign(unknowns(), 0.0);
    pair_idx_.clear();
    return;
  }
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(n_ * d * (d + 1) / 2 + pairs.size() * d * d);
  for (std::size_t i = 0; i < n_; ++i)
    for (int r = 0; r < d; ++r)
      for (int c = 0; c <= r; ++c) trip.emplace_back(d * i + r, d * i + c, 0.0);
  for (const auto& pr : pairs) {
    if (p.motion[pr.j] != Motion::Mobile) continue;
    const int hi = std::max(pr.i, pr.j), lo = std::min(pr.i, pr.j);
    for (int r = 0; r < d; ++r)
      for (int c = 0; c < d; ++c) trip.emplace_back(d * hi + r, d * lo + c, 0.0);
  }
  for (const auto& [r, c] : extra_entries) trip.emplace_back(r, c, 0.0);
  a_.resize(nu, nu);
  a_.setFromTriplets(trip.begin(), trip.end());
  a_.makeCompressed();

  diag_idx_.assign(n_ * d * d, -1);
  for (std::size_t i = 0; i < n_; ++i)
    for (int r = 0; r < d; ++r)
      for (int c = 0; c <= r; ++c)
        diag_idx_[(i * d + r) * d + c] =
            index(static_cast<int>(d * i + r), static_cast<int>(d * i + c));
  pair_idx_.assign(pairs.size() * d * d, -1);
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& pr = pairs[k];
    if (p.motion[pr.j] != Motion::Mobile) continue;
    const int hi = std::max(pr.i, pr.j), lo = std::min(pr.i, pr.j);
    for (int r = 0; r < d; ++r)
      for (int c = 0; c < d; ++c) pair_idx_[(k * d + r) * d + c] = index(d * hi + r, d * lo + c);
  }
  llt_->analyze(a_);
  ++analyses_;
}

void ResistanceSystem::add_low_rank(const VecX& w, double k, const VecX& dg, double w_wall,
                                    double wall_rhs_change) {
  if (!factor_of_a_ || diagonal_only_)
    throw std::logic_error("ResistanceSystem: low-rank terms need the factor of A");
  if (w_wall != 0.0) {
    b_ += (k * w_wall) * w;
    c_ += k * w_wall * w_wall;
    if (a_inverse_b_.size() > 0)
      a_inverse_b_updates_.emplace_back(static_cast<Eigen::Index>(lr_.size()), k * w_wall);
  }
  wall_rhs_ += wall_rhs_change;
  LowRankTerm t{{}, k};
  for (Eigen::Index i = 0; i < w.size(); ++i)
    if (w[i] != 0.0) t.w.emplace_back(i, w[i]);
  lr_.push_back(std::move(t));
  ++low_rank_terms_;
  g_ += dg;
  lr_ready_ = false;
}

bool ResistanceSystem::low_rank_pays(std::size_t more) const {
  if (!factor_of_a_ || diagonal_only_) return false;
  if (max_low_rank_terms_ > 0) return lr_.size() + more <= max_low_rank_terms_;
  const double ratio = llt_->solves_per_factorisation();
  // Unknown cost ratio (Eigen's factorisation): always update.
  return ratio <= 0.0 || static_cast<double>(lr_.size() + more) <= std::max(ratio, 4.0);
}

double ResistanceSystem::dot(const LowRankTerm& t, const VecX& x) const {
  double s = 0.0;
  for (const auto& [i, v] : t.w) s += v * x[i];
  return s;
}

bool ResistanceSystem::prepare() {
  if (factor_of_a_) return true;
  ++factorisations_;
  factor_of_a_ = llt_->factorize(a_);
  a_inverse_b_.resize(0);
  a_inverse_b_updates_.clear();
  return factor_of_a_;
}

VecX ResistanceSystem::apply_inverse(const VecX& x, VecX* a_inverse_x) {
  VecX y;
  if (a_inverse_x != nullptr && a_inverse_x->size() == x.size()) {
    y = *a_inverse_x;
  } else {
    y = llt_->solve(x);
    if (a_inverse_x != nullptr) *a_inverse_x = y;
  }
  if (lr_.empty()) return y;
  // Woodbury: (A + W K W^T)^-1 = A^-1 - Z (K^-1 + W^T Z)^-1 Z^T, Z = A^-1 W. The columns of Z
  // of earlier passes are kept: a pass solves its new terms' columns, as one block.
  const auto r = static_cast<Eigen::Index>(lr_.size());
  if (!lr_ready_) {
    lr_z_.conservativeResize(x.size(), r);
    if (const Eigen::Index fresh = r - lr_z_cols_; fresh > 0) {
      Eigen::MatrixXd w = Eigen::MatrixXd::Zero(x.size(), fresh);
      for (Eigen::Index c = 0; c < fresh; ++c)
        for (const auto& [i, v] : lr_[lr_z_cols_ + c].w) w(i, c) = v;
      lr_z_.rightCols(fresh) = llt_->solve(w);
    }
    lr_z_cols_ = r;
    Eigen::MatrixXd s(r, r);
    for (Eigen::Index a = 0; a < r; ++a)
      for (Eigen::Index b = 0; b < r; ++b) s(a, b) = dot(lr_[a], lr_z_.col(b));
    for (Eigen::Index a = 0; a < r; ++a) s(a, a) += 1.0 / lr_[a].k;
    lr_s_.emplace(s);
    lr_ready_ = true;
  }
  VecX wy(r);
  for (Eigen::Index a = 0; a < r; ++a) wy[a] = dot(lr_[a], y);
  ++low_rank_solves_;
  return y - lr_z_ * lr_s_->solve(wy);
}

void ResistanceSystem::clear() {
  factor_of_a_ = false;
  lr_.clear();
  a_inverse_b_updates_.clear();
  lr_z_cols_ = 0;
  lr_ready_ = false;
  if (diagonal_only_)
    std::fill(diag_.begin(), diag_.end(), 0.0);
  else
    std::fill(a_.valuePtr(), a_.valuePtr() + a_.nonZeros(), 0.0);
  g_.setZero();
  b_.setZero();
  c_ = 0.0;
  wall_rhs_ = 0.0;
  mult_ = 0.0;
}

template <class Body>
void ResistanceSystem::add_self_of(int i, const Body& resistance, const Body& force) {
  for (int r = 0; r < dof_; ++r) {
    const std::size_t row = static_cast<std::size_t>(dof_) * i + r;
    if (diagonal_only_)
      diag_[row] += resistance[r];
    else
      a_.valuePtr()[diag_idx_[(row)*dof_ + r]] += resistance[r];
    g_[static_cast<Eigen::Index>(row)] += force[r];
  }
}

template <class PairType, class Matrix, class Vector, class Body>
void ResistanceSystem::add_pair(std::size_t k, const PairType& pr, const Matrix& m, const Vector& f,
                                const Body& known_j, bool j_mobile, bool j_floating) {
  // B: components of one particle's generalised velocity; j's start at B, its y velocity at
  // B + 1.
  constexpr int B = Body::RowsAtCompileTime;
  const int d = dof_;
  double* val = diagonal_only_ ? nullptr : a_.valuePtr();
  // Right-hand side: spring force minus the resistance against j's known velocity.
  const Vector rhs = f - m.template rightCols<B>() * known_j;
  for (int r = 0; r < d; ++r) g_[d * pr.i + r] += rhs[r];
  if (!diagonal_only_) {
    for (int r = 0; r < d; ++r)
      for (int c = 0; c <= r; ++c) val[diag_idx_[(pr.i * d + r) * d + c]] += m(r, c);
  } else {
    for (int r = 0; r < d; ++r) diag_[d * pr.i + r] += m(r, r);
  }
  if (j_mobile) {
    for (int r = 0; r < d; ++r) g_[d * pr.j + r] += rhs[B + r];
    if (!diagonal_only_) {
      for (int r = 0; r < d; ++r)
        for (int c = 0; c <= r; ++c) val[diag_idx_[(pr.j * d + r) * d + c]] += m(B + r, B + c);
      // Block of row particle max(i, j) and column particle min(i, j).
      const bool j_hi = pr.j > pr.i;
      for (int r = 0; r < d; ++r)
        for (int c = 0; c < d; ++c)
          val[pair_idx_[(k * d + r) * d + c]] += j_hi ? m(B + r, c) : m(r, B + c);
    } else {
      for (int r = 0; r < d; ++r) diag_[d * pr.j + r] += m(B + r, B + r);
    }
  } else if (j_floating) {
    for (int r = 0; r < d; ++r) b_[d * pr.i + r] += m(r, B + 1);
    c_ += m(B + 1, B + 1);
    wall_rhs_ += rhs[B + 1];
  }
}

// Discs and spheres.
template void ResistanceSystem::set_pattern<Dim2>(std::size_t, const std::vector<Pair>&,
                                                  const Particles&, bool, std::size_t,
                                                  const std::vector<std::pair<int, int>>&);
template void ResistanceSystem::set_pattern<Dim3>(std::size_t, const std::vector<Pair3>&,
                                                  const Particles3&, bool, std::size_t,
                                                  const std::vector<std::pair<int, int>>&);
template void ResistanceSystem::add_self_of(int, const Vec3&, const Vec3&);
template void ResistanceSystem::add_self_of(int, const Vec6&, const Vec6&);
template void ResistanceSystem::add_pair(std::size_t, const Pair&, const Mat6&, const Vec6&,
                                         const Vec3&, bool, bool);
template void ResistanceSystem::add_pair(std::size_t, const Pair3&, const Mat12&, const Vec12&,
                                         const Vec6&, bool, bool);

void ResistanceSystem::add_value(int row, int col, double v) {
  a_.valuePtr()[index(row, col)] += v;
}

bool ResistanceSystem::solve_with_multiplier(VecX& u, const VecX& e, double& m) {
  if (diagonal_only_ || !prepare()) return false;
  u = apply_inverse(g_);
  const VecX u1 = apply_inverse(e);
  // e . (u + m u1) = 0; e . A^-1 e > 0 for e != 0.
  m = -e.dot(u) / e.dot(u1);
  u += m * u1;
  mult_e_ = e;
  mult_ = m;
  return u.allFinite() && std::isfinite(m);
}

bool ResistanceSystem::solve(VecX& u) {
  if (diagonal_only_) {
    u = g_.array() / Eigen::Map<const VecX>(diag_.data(), g_.size()).array();
    return u.allFinite();
  }
  if (!prepare()) return false;
  u = apply_inverse(g_);
  return u.allFinite();
}

bool ResistanceSystem::solve_with_floating_wall(VecX& u, double load, double free_fall_cap,
                                                double& v, bool& capped) {
  VecX u1;
  if (diagonal_only_) {
    const auto diag = Eigen::Map<const VecX>(diag_.data(), g_.size()).array();
    u = g_.array() / diag;
    u1 = b_.array() / diag;
  } else {
    if (!prepare()) return false;
    u = apply_inverse(g_);
    // A^-1 b of the factor is kept; a sticking pass's change of the wall column is a sum of
    // its terms' w, whose A^-1 w the Woodbury step above has just solved.
    for (const auto& [term, coef] : a_inverse_b_updates_) a_inverse_b_ += coef * lr_z_.col(term);
    a_inverse_b_updates_.clear();
    u1 = apply_inverse(b_, &a_inverse_b_);
  }
  // Schur complement of the bordered system [[A, b], [b^T, c]].
  const double schur = c_ - b_.dot(u1);
  const double rhs = wall_rhs_ - load - b_.dot(u);
  capped = !(schur > 0.0 && std::abs(rhs) < free_fall_cap * schur);
  if (!capped) {
    v = rhs / schur;
  } else {
    // Nothing (or almost nothing) holds the wall: it falls at a capped speed onto the packing.
    v = std::copysign(free_fall_cap, rhs);
  }
  u -= v * u1;
  return u.allFinite() && std::isfinite(v);
}

double ResistanceSystem::residual(const VecX& u, double v) const {
  VecX au;
  if (diagonal_only_) {
    au = Eigen::Map<const VecX>(diag_.data(), g_.size()).cwiseProduct(u);
  } else {
    au = a_.selfadjointView<Eigen::Lower>() * u;
  }
  for (const LowRankTerm& t : lr_) {
    const double kwu = t.k * dot(t, u);
    for (const auto& [i, w] : t.w) au[i] += kwu * w;
  }
  au += v * b_;
  VecX g = g_;
  if (mult_e_.size() == g.size()) g += mult_ * mult_e_;
  const double gn = g.norm();
  return (au - g).norm() / (gn > 0 ? gn : 1.0);
}

}  // namespace sheardiff
