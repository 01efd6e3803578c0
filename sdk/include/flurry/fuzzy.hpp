// Fuzzy values: a central value and the variability allowed around it (the seed's
// "60 frames ± 25%").
#pragma once

#include <cmath>

#include "flurry/error.hpp"
#include "flurry/random.hpp"

namespace flurry {

/// A scalar drawn per particle: center ± spread. Uniform draws are in
/// [center - spread, center + spread]; Normal draws have standard deviation `spread`.
struct Fuzzy {
  enum class Distribution { Uniform, Normal };

  float center = 0.0f;
  float spread = 0.0f;
  Distribution distribution = Distribution::Uniform;

  Fuzzy() = default;
  Fuzzy(float c) : center(c) {}  // NOLINT: a plain number is a value with no spread
  Fuzzy(float c, float s, Distribution d = Distribution::Uniform)
      : center(c), spread(s), distribution(d) {}

  /// "value ± percent %", as in the seed: Fuzzy::percent(60, 25) draws from [45, 75].
  static Fuzzy percent(float c, float pct) { return Fuzzy(c, std::abs(c) * pct / 100.0f); }

  bool constant() const { return spread == 0.0f; }

  /// One draw from `rng` (the uniforms in the order the device draws them, kernels/domain.h).
  float sample(Random& rng) const;

  /// Throws InvalidArgument naming `name` if the value is not finite or the spread negative.
  void validate(const char* name) const {
    if (!std::isfinite(center)) throw InvalidArgument(name, "center is not finite");
    if (!std::isfinite(spread) || spread < 0.0f)
      throw InvalidArgument(name, "spread must be finite and >= 0");
  }
};

}  // namespace flurry
