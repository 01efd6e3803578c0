// How the CPU backend cuts its pass over a group: knobs for the tests and the benchmarks
// (tests/ and bench/ reach sdk/src through their private include path), not public API —
// results are bitwise the same for any of them.
#pragma once

#include <cstddef>

namespace flurry {
class Context;
}

namespace flurry::detail {

struct PassOptions {
  /// Particles per block of the fused pass: every action runs over a block while it is in
  /// cache, so memory is read and written once per step. 0 picks the default.
  std::size_t blockSize = 0;
  /// false runs one pass over the whole group per action: the unfused baseline that the
  /// benchmarks compare against.
  bool fused = true;
};

/// Applies from the context's next step on.
void setPassOptions(Context& context, const PassOptions& options);
PassOptions passOptions(const Context& context);

}  // namespace flurry::detail
