// The fused pass is compute-bound at SSE2 width (a bounce is ~60 flops per particle), and so
// is writing newborns (random numbers, shapes): both are compiled once per instruction set
// (sdk/CMakeLists.txt) and picked here at run time.
#include <cstdlib>
#include <cstring>

#include "../backend.hpp"
#include "../emission_plan.hpp"

namespace flurry::detail {

#define FLURRY_DECLARE_VARIANT(isa)                                                              \
  namespace isa {                                                                                \
  void actFusedImpl(GroupImpl& g, const StepParams& sp);                                         \
  void writeNewborns(GroupImpl& g, const StepParams& sp, const BirthRun* runs,                   \
                     const std::uint64_t* runStart, std::size_t runCount, std::size_t accepted); \
  }
FLURRY_DECLARE_VARIANT(baseline)
#ifdef FLURRY_HAS_ISA_VARIANTS
FLURRY_DECLARE_VARIANT(avx2)
FLURRY_DECLARE_VARIANT(avx512)
#endif
#undef FLURRY_DECLARE_VARIANT

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
// Picked once per process: what fusedPassIsa() says is what runs.
Impl chosen() {
  static const Impl impl = pick();
  return impl;
}
}  // namespace

const char* fusedPassIsa() {
  const Impl impl = chosen();
#ifdef FLURRY_HAS_ISA_VARIANTS
  if (impl == avx512::actFusedImpl) return "avx512";
  if (impl == avx2::actFusedImpl) return "avx2";
#endif
  (void)impl;
  return "baseline";
}

void actFused(GroupImpl& g, const StepParams& sp) {
  static const Impl impl = chosen();
  impl(g, sp);
}

void writeNewborns(GroupImpl& g, const StepParams& sp, const BirthRun* runs,
                   const std::uint64_t* runStart, std::size_t runCount, std::size_t accepted) {
  using Write = decltype(&baseline::writeNewborns);
  // The same instruction set as the fused pass.
  static const Write write = [] {
    const Impl impl = chosen();
#ifdef FLURRY_HAS_ISA_VARIANTS
    if (impl == avx512::actFusedImpl) return &avx512::writeNewborns;
    if (impl == avx2::actFusedImpl) return &avx2::writeNewborns;
#endif
    (void)impl;
    return &baseline::writeNewborns;
  }();
  write(g, sp, runs, runStart, runCount, accepted);
}

}  // namespace flurry::detail
