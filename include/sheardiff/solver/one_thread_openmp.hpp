#pragma once

namespace sheardiff {

// True when CHOLMOD's OpenMP parallel regions run directly on the calling thread (sheardiff's
// GOMP_parallel, src/solver/one_thread_openmp.cpp, is the one the dynamic linker found, and
// OMP_THREAD_LIMIT is 1), i.e. without libgomp's per-region team and barrier.
bool openmp_regions_run_inline();

}  // namespace sheardiff
