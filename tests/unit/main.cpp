// The unit tests' main: GoogleTest's, after the solver environment sheardiff itself runs with
// (include/sheardiff/solver/blas_kernels.hpp), so that a test factorises with the kernels a run
// uses.
#include <gtest/gtest.h>

#include "sheardiff/solver/blas_kernels.hpp"

int main(int argc, char** argv) {
  sheardiff::set_solver_environment(argv);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
