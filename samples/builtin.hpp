// Built-in sample effects: the effect files of samples/effects/, embedded into the tool at
// build time so that `flurry run fountain` works from any build tree and after install.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "flurry/effect.hpp"
#include "flurry/flurry.hpp"

namespace flurry::samples {

struct Sample {
  std::string name;
  std::string description;
  /// Builds the effect in `ctx`; `capacity` > 0 caps every group's capacity.
  std::function<void(Context& ctx, std::size_t capacity)> build;
  std::string file;       ///< "fountain.json"
  std::string_view json;  ///< the embedded file's text
  /// The loaded effect (null if the embedded file failed to load; description says why).
  std::shared_ptr<const Effect> effect;
};

/// Every built-in effect, sorted by name.
const std::vector<Sample>& builtinSamples();
const Sample* findSample(const std::string& name);

/// An effect by built-in name or by path: a path if such a file exists or the argument ends in
/// ".json", else a built-in name. Throws EffectError (an unknown name suggests the nearest).
Effect loadEffectOrSample(const std::string& nameOrPath, const EffectLoadOptions& options = {});

/// The fountain (samples/effects/fountain.json): a disc emitter spraying upwards, gravity, a
/// bouncy ground, death by age; `rate` particles per second with lifetimes of `lifetime`
/// s ± 10 %.
Group& buildFountain(Context& ctx, std::size_t capacity, double rate, float lifetime);

namespace detail {
struct EmbeddedEffect {
  const char* file;
  const char* data;
  std::size_t size;
};
/// Generated from samples/effects/*.json; ends with a null entry.
extern const EmbeddedEffect kEmbeddedEffects[];
}  // namespace detail

}  // namespace flurry::samples
