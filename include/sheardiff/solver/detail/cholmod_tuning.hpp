#pragma once
// CHOLMOD's own types, kept out of the solver's public headers: only the factorisation
// (src/solver/sparse_cholesky.cpp), its tests and the solver benchmark include this.
#include <cholmod.h>

namespace sheardiff {

// The ordering and supernode settings sheardiff uses for CHOLMOD on the matrix of discs
// (dimension 2) or spheres (3) (measured, see src/solver/sparse_cholesky.cpp).
void tune_cholmod(cholmod_common& c, int dimension = 2);

}  // namespace sheardiff
