#include <gtest/gtest.h>

#include <cstdlib>

#include "sheardiff/solver/blas_kernels.hpp"

using sheardiff::openblas_coretype_upgrade;
using sheardiff::VectorIsa;

// Debian 12's OpenBLAS 0.3.21 on an Intel Xeon of family 6 model 207: generic SSE3 kernels on
// an AVX-512 CPU with BF16. The factorisation of 1000 spheres took 2-3x as long there
// (docs/performance.md "The BLAS kernels").
TEST(BlasKernels, GenericKernelsOnAVX512AreUpgraded) {
  EXPECT_EQ(openblas_coretype_upgrade("Prescott", VectorIsa::avx512_bf16), "Cooperlake");
  EXPECT_EQ(openblas_coretype_upgrade("Prescott", VectorIsa::avx512), "SkylakeX");
  EXPECT_EQ(openblas_coretype_upgrade("Nehalem", VectorIsa::avx512), "SkylakeX");
  EXPECT_EQ(openblas_coretype_upgrade("Haswell", VectorIsa::avx512), "SkylakeX");
  EXPECT_EQ(openblas_coretype_upgrade("Sandybridge", VectorIsa::avx2), "Haswell");
  EXPECT_EQ(openblas_coretype_upgrade("Prescott", VectorIsa::avx2), "Haswell");
}

TEST(BlasKernels, KernelsAsWideAsTheCPUAreKept) {
  EXPECT_EQ(openblas_coretype_upgrade("Cooperlake", VectorIsa::avx512_bf16), std::nullopt);
  EXPECT_EQ(openblas_coretype_upgrade("SkylakeX", VectorIsa::avx512_bf16), std::nullopt);
  EXPECT_EQ(openblas_coretype_upgrade("Zen", VectorIsa::avx2), std::nullopt);
  EXPECT_EQ(openblas_coretype_upgrade("Haswell", VectorIsa::avx2), std::nullopt);
  EXPECT_EQ(openblas_coretype_upgrade("Prescott", VectorIsa::older), std::nullopt);
}

TEST(BlasKernels, NeverStepsDownOrGuessesAnUnknownSet) {
  // Wider than the CPU's class as this code sees it (a newer OpenBLAS's own choice) or a name not
  // in the list: left to OpenBLAS.
  EXPECT_EQ(openblas_coretype_upgrade("SkylakeX", VectorIsa::avx2), std::nullopt);
  EXPECT_EQ(openblas_coretype_upgrade("SapphireRapids", VectorIsa::avx512), std::nullopt);
  EXPECT_EQ(openblas_coretype_upgrade("Zen5", VectorIsa::older), std::nullopt);
  EXPECT_EQ(openblas_coretype_upgrade("", VectorIsa::avx512), std::nullopt);
}

// tests/unit/main.cpp sets the kernels as sheardiff does: the ones loaded here are as wide as
// the CPU allows (unless the caller set OPENBLAS_CORETYPE).
TEST(BlasKernels, TheTestsRunTheKernelsARunUses) {
  const auto loaded = sheardiff::openblas_kernels();
  if (!loaded) GTEST_SKIP() << "the BLAS is not OpenBLAS";
  const auto upgrade = openblas_coretype_upgrade(*loaded, sheardiff::cpu_vector_isa());
  // Narrower kernels with OPENBLAS_CORETYPE set are the caller's choice, which main keeps.
  if (upgrade && std::getenv("OPENBLAS_CORETYPE") != nullptr) GTEST_SKIP() << "caller's choice";
  EXPECT_EQ(upgrade, std::nullopt) << "OpenBLAS runs " << *loaded;
}
