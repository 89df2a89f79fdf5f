#include "sheardiff/solver/blas_kernels.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <utility>

namespace sheardiff {

VectorIsa cpu_vector_isa() {
  __builtin_cpu_init();
  const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                      __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq");
  if (avx512)
    return __builtin_cpu_supports("avx512bf16") ? VectorIsa::avx512_bf16 : VectorIsa::avx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return VectorIsa::avx2;
  return VectorIsa::older;
}

std::optional<std::string> openblas_kernels() {
  using CoreName = char* (*)();
  const auto name = reinterpret_cast<CoreName>(dlsym(RTLD_DEFAULT, "openblas_get_corename"));
  if (name == nullptr) return std::nullopt;
  return std::string(name());
}

namespace {
// OpenBLAS's x86-64 kernel sets (DYNAMIC_ARCH) by the vectors they use: 0 SSE, 1 AVX, 2 AVX2,
// 3 AVX-512.
constexpr std::array<std::pair<std::string_view, int>, 20> kKernelWidth{{
    {"Prescott", 0},   {"Core2", 0},       {"Penryn", 0},      {"Dunnington", 0},
    {"Nehalem", 0},    {"Atom", 0},        {"Opteron", 0},     {"Opteron(SSE3)", 0},
    {"Barcelona", 0},  {"Bobcat", 0},      {"Sandybridge", 1}, {"Bulldozer", 1},
    {"Piledriver", 1}, {"Steamroller", 1}, {"Excavator", 1},   {"Haswell", 2},
    {"Zen", 2},        {"SkylakeX", 3},    {"Cooperlake", 3},  {"SapphireRapids", 3},
}};
}  // namespace

std::optional<std::string> openblas_coretype_upgrade(std::string_view running, VectorIsa cpu) {
  int width = -1;
  for (const auto& [name, w] : kKernelWidth)
    if (name == running) width = w;
  if (width < 0) return std::nullopt;
  switch (cpu) {
    case VectorIsa::avx512_bf16:
      if (width < 3) return "Cooperlake";
      break;
    case VectorIsa::avx512:
      if (width < 3) return "SkylakeX";
      break;
    case VectorIsa::avx2:
      if (width < 2) return "Haswell";
      break;
    case VectorIsa::older:
      break;
  }
  return std::nullopt;
}

void set_solver_environment(char** argv) {
  bool changed = false;
  // CHOLMOD (Debian's build) opens OpenMP regions with a fixed num_threads clause inside its
  // supernodal factorisation; only OMP_THREAD_LIMIT, read when libgomp loads, caps them. Spare
  // threads spin and cost a shared 2-core machine ~40 %, and sweeps already run one process per
  // core, so the solver runs single-threaded unless the caller sets OMP_THREAD_LIMIT itself.
  if (std::getenv("OMP_THREAD_LIMIT") == nullptr) {
    setenv("OMP_THREAD_LIMIT", "1", 1);
    changed = true;
  }
  if (std::getenv("OPENBLAS_CORETYPE") == nullptr) {
    if (const auto running = openblas_kernels()) {
      if (const auto wider = openblas_coretype_upgrade(*running, cpu_vector_isa())) {
        setenv("OPENBLAS_CORETYPE", wider->c_str(), 1);
        changed = true;
      }
    }
  }
  if (changed) execv("/proc/self/exe", argv);  // returns only on failure: then run as we are
}

}  // namespace sheardiff
