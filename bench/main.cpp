// The benchmarks' main: Google Benchmark's, after the solver environment sheardiff itself runs
// with (one thread, OpenBLAS kernels that use the CPU: include/sheardiff/solver/blas_kernels.hpp),
// so that a benchmark times what a run does.
#include <benchmark/benchmark.h>

#include "sheardiff/solver/blas_kernels.hpp"

int main(int argc, char** argv) {
  sheardiff::set_solver_environment(argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
