#pragma once
// CHOLMOD's own types, kept out of the solver's public headers: only the factorisation
// (src/solver/sparse_cholesky.cpp), its tests and the solver benchmark include this.
#include <cholmod.h>

#include <Eigen/CholmodSupport>

namespace sheardiff {

using Supernodal = Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>;

// Eigen's wrapper with CHOLMOD's factor in reach (its permutation, its supernodes).
class SupernodalWithFactor : public Supernodal {
 public:
  const cholmod_factor* factor() const { return m_cholmodFactor; }
};

// The ordering and supernode settings sheardiff uses for CHOLMOD on the matrix of discs
// (dimension 2) or spheres (3) (measured, see src/solver/sparse_cholesky.cpp).
void tune_cholmod(cholmod_common& c, int dimension = 2);

// Threads of OpenBLAS, behind CHOLMOD's supernodal kernels; a no-op with another BLAS.
void set_blas_threads(int threads);

}  // namespace sheardiff
