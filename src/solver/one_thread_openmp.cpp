#include "sheardiff/solver/one_thread_openmp.hpp"

#include <dlfcn.h>

// Debian's CHOLMOD wraps loops of its supernodal factorisation in OpenMP parallel regions, one
// or more per supernode: hundreds per factorisation. sheardiff runs them with one thread
// (OMP_THREAD_LIMIT=1, docs/performance.md "Threads"), and libgomp still opens a team for each
// and closes it with a barrier whose wake-up is a futex system call. perf put 30 % of a running
// N = 1000, J = 1e-4 sweep point in libgomp and the kernel's futex path; two runs sharing the
// 2 cores, as a sweep's workers do, take 1.65-1.82x less wall time without it
// (bench/two_workers.sh, docs/performance.md "What cut the cost per strain"), one run alone on an
// idle machine 1.0-1.5x less.
//
// This definition is found before libgomp's by the dynamic linker (the executable comes first
// in the lookup order, and CHOLMOD's reference exports it from there). With one thread it runs
// the region on the calling thread, which is what a one-thread team does: CHOLMOD's regions are
// statically scheduled loops that ask omp_get_num_threads() (1 outside a team) and
// omp_get_thread_num() (0), so every loop iteration runs, in order, on this thread, and the
// arithmetic is unchanged. With more threads allowed it hands the region to libgomp.

namespace {
using GompParallel = void (*)(void (*)(void*), void*, unsigned, unsigned);

// libgomp's own entry points, looked up once (thread-safe static initialisation) from the
// copy CHOLMOD loaded; sheardiff itself does not link libgomp.
GompParallel libgomp_parallel() {
  static const auto real =
      reinterpret_cast<GompParallel>(dlvsym(RTLD_NEXT, "GOMP_parallel", "GOMP_4.0"));
  return real;
}

int thread_limit() {
  using Query = int (*)();
  static const auto query = reinterpret_cast<Query>(dlsym(RTLD_DEFAULT, "omp_get_thread_limit"));
  return query ? query() : 1;
}
}  // namespace

extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned num_threads, unsigned flags) {
  if (num_threads != 1 && thread_limit() > 1) {
    if (const GompParallel real = libgomp_parallel()) {
      real(fn, data, num_threads, flags);
      return;
    }
  }
  fn(data);
}

namespace sheardiff {

bool openmp_regions_run_inline() {
  const auto found = reinterpret_cast<GompParallel>(dlsym(RTLD_DEFAULT, "GOMP_parallel"));
  return found == &GOMP_parallel && thread_limit() == 1;
}

}  // namespace sheardiff
