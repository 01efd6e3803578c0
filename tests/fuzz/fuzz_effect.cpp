// libFuzzer target for the effect loader: any input must load or be refused with an
// EffectError; anything else escaping (another exception, a crash, a sanitizer report, a
// hang) is a bug. Loaded effects are also built into a context so the core's checks run.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const flurry::Effect fx = flurry::parseEffect(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    flurry::ContextOptions co = fx.contextOptions();
    co.threads = 1;
    flurry::Context ctx(co);
    fx.build(ctx, 16);  // tiny groups: the checks do not depend on capacity
  } catch (const flurry::EffectError&) {
  }
  return 0;
}
