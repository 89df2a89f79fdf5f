#pragma once
// Which BLAS kernels the factorisation runs on. The supernodal Cholesky of a packing of spheres
// spends most of a step in dense BLAS on its supernodes, and OpenBLAS picks its kernels for the
// CPU when it loads. An OpenBLAS older than the CPU does not know it and falls back to its
// generic SSE3 kernels ("Prescott"): Debian 12's 0.3.21 does so on Intel Xeons of family 6
// model 207 (AVX-512), where a factorisation of 1000 spheres then takes 2-3 times as long
// (docs/performance.md "The BLAS kernels"). OPENBLAS_CORETYPE, read when the library loads,
// names the kernels instead.
#include <optional>
#include <string>
#include <string_view>

namespace sheardiff {

// The widest vector instructions the CPU offers that OpenBLAS has kernels for.
enum class VectorIsa {
  older,        // below AVX2 + FMA
  avx2,         // AVX2 and FMA: OpenBLAS's Haswell kernels
  avx512,       // AVX-512 F, BW, VL and DQ: SkylakeX
  avx512_bf16,  // and BF16: Cooperlake (the same double-precision kernels as SkylakeX)
};

VectorIsa cpu_vector_isa();

// The kernel set OpenBLAS chose at load ("Cooperlake", "Prescott"), or nullopt when the BLAS
// the solver loaded is not OpenBLAS.
std::optional<std::string> openblas_kernels();

// The OPENBLAS_CORETYPE that makes OpenBLAS use what a CPU of class `cpu` offers, when the kernels
// it `running` are a known set of narrower vectors; nullopt when they are as wide (or unknown to
// this list: never step down).
std::optional<std::string> openblas_coretype_upgrade(std::string_view running, VectorIsa cpu);

// For a program's main, first thing: sets OMP_THREAD_LIMIT=1 (docs/performance.md "Threads")
// and the OPENBLAS_CORETYPE above where the caller's environment does not set them, and then
// re-executes the program once, as the libraries read both only when they load. Returns if
// nothing needed setting or the re-execution failed (the program then runs as it is).
void set_solver_environment(char** argv);

}  // namespace sheardiff
