#include <dlfcn.h>
#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <thread>

#include "sheardiff/solver/one_thread_openmp.hpp"
#include "sheardiff/solver/sparse_cholesky.hpp"

extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned num_threads, unsigned flags);

namespace {

struct RegionLog {
  int calls = 0;
  int team_size = -1;
  int thread_num = -1;
  std::thread::id thread;
};

// libgomp's queries, from the copy CHOLMOD loaded (the tests do not link libgomp).
int omp_query(const char* name) {
  using Query = int (*)();
  const auto q = reinterpret_cast<Query>(dlsym(RTLD_DEFAULT, name));
  return q ? q() : -1;
}

void record(void* data) {
  auto* log = static_cast<RegionLog*>(data);
  ++log->calls;
  log->team_size = omp_query("omp_get_num_threads");
  log->thread_num = omp_query("omp_get_thread_num");
  log->thread = std::this_thread::get_id();
}

}  // namespace

// ctest runs the unit tests with OMP_THREAD_LIMIT=1, as sheardiff runs itself.
TEST(OneThreadOpenMP, CholmodsRegionsResolveToTheInlineDefinition) {
  // Fails if the executable stops exporting GOMP_parallel (libgomp's would then be found).
  EXPECT_TRUE(sheardiff::openmp_regions_run_inline());
}

TEST(OneThreadOpenMP, ARegionRunsOnceOnTheCallingThreadAsATeamOfOne) {
  RegionLog log;
  // Asking for 4 threads, as CHOLMOD's num_threads clause does.
  GOMP_parallel(&record, &log, 4, 0);
  EXPECT_EQ(log.calls, 1);
  EXPECT_EQ(log.team_size, 1);
  EXPECT_EQ(log.thread_num, 0);
  EXPECT_EQ(log.thread, std::this_thread::get_id());
}

TEST(OneThreadOpenMP, CholmodStillSolvesThroughIt) {
  // A 1D Laplacian plus a diagonal shift (SPD, with fill-free supernodes of every size) of 600
  // unknowns: CHOLMOD's supernodal factorisation runs its parallel regions here; the solution
  // must satisfy the system to round-off.
  const int n = 600;
  Eigen::SparseMatrix<double> a(n, n);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2.5);
    if (i + 1 < n) t.emplace_back(i + 1, i, -1.0);
    if (i + 7 < n) t.emplace_back(i + 7, i, -0.2);
  }
  a.setFromTriplets(t.begin(), t.end());
  auto chol = sheardiff::make_sparse_cholesky("cholmod");
  chol->analyze(a);
  ASSERT_TRUE(chol->factorize(a));
  Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
  const Eigen::VectorXd x = chol->solve(b);
  const Eigen::SparseMatrix<double> full =
      Eigen::SparseMatrix<double>(a.selfadjointView<Eigen::Lower>());
  EXPECT_LT((full * x - b).norm() / b.norm(), 1e-13);
}
