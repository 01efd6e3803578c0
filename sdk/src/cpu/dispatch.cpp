// The fused pass is compute-bound at SSE2 width (a bounce is ~60 flops per particle), so it
// is compiled once per instruction set (sdk/CMakeLists.txt) and picked here at run time.
#include <cstdlib>
#include <cstring>

#include "../backend.hpp"

namespace flurry::detail {

namespace baseline {
void actFusedImpl(GroupImpl& g, const StepParams& sp);
}
#ifdef FLURRY_HAS_ISA_VARIANTS
namespace avx2 {
void actFusedImpl(GroupImpl& g, const StepParams& sp);
}
namespace avx512 {
void actFusedImpl(GroupImpl& g, const StepParams& sp);
}
#endif

namespace {
using Impl = void (*)(GroupImpl&, const StepParams&);

Impl pick() {
  // FLURRY_ISA=baseline|avx2|avx512 forces a variant (for comparisons and bug hunts).
  const char* want = std::getenv("FLURRY_ISA");
#ifdef FLURRY_HAS_ISA_VARIANTS
  __builtin_cpu_init();
  const bool has512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                      __builtin_cpu_supports("avx512vl");
  const bool has2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (want && std::strcmp(want, "baseline") == 0) return baseline::actFusedImpl;
  if (want && std::strcmp(want, "avx2") == 0 && has2) return avx2::actFusedImpl;
  if (has512 && !(want && std::strcmp(want, "avx2") == 0)) return avx512::actFusedImpl;
  if (has2) return avx2::actFusedImpl;
#endif
  (void)want;
  return baseline::actFusedImpl;
}
}  // namespace

const char* fusedPassIsa() {
  const Impl impl = pick();
#ifdef FLURRY_HAS_ISA_VARIANTS
  if (impl == avx512::actFusedImpl) return "avx512";
  if (impl == avx2::actFusedImpl) return "avx2";
#endif
  (void)impl;
  return "baseline";
}

void actFused(GroupImpl& g, const StepParams& sp) {
  static const Impl impl = pick();
  impl(g, sp);
}

}  // namespace flurry::detail
