// Built-in sample effects, defined in code until effect files arrive.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "flurry/flurry.hpp"

namespace flurry::samples {

struct Sample {
  std::string name;
  std::string description;
  /// Builds the effect in `ctx`; `capacity` bounds the main group.
  std::function<void(Context& ctx, std::size_t capacity)> build;
};

const std::vector<Sample>& builtinSamples();
const Sample* findSample(const std::string& name);

/// The fountain: a disc emitter spraying upwards, gravity, a bouncy ground, death by age.
/// `rate` particles per second with lifetimes of `lifetime` s ± 10 %.
Group& buildFountain(Context& ctx, std::size_t capacity, double rate, float lifetime);

}  // namespace flurry::samples
