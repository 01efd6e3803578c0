// Counter-based random numbers (Philox4x32-10, Salmon et al., SC'11).
//
// A draw is a pure function of (seed, counter), so every particle has its own stream keyed
// by (particle id, step, stream) and a run is the same on 1 thread or 16, and on the CPU
// and OpenCL backends (both compute kernels/philox.h).
#pragma once

#include <cmath>
#include <cstdint>

namespace flurry {

/// One Philox4x32-10 block: 4 random 32-bit words for a 128-bit counter and 64-bit key.
struct Philox4x32 {
  struct Block {
    std::uint32_t v[4];
  };
  /// The rounds are written once for both backends (kernels/philox.h, with the constants).
  static Block generate(std::uint32_t c0, std::uint32_t c1, std::uint32_t c2, std::uint32_t c3,
                        std::uint32_t k0, std::uint32_t k1) noexcept;
};

/// Maps 32 random bits to a float in [0, 1) with 24 bits of resolution.
float uniformFloat(std::uint32_t bits) noexcept;

namespace detail {
/// A standard normal from two uniforms in [0, 1) (kernels/domain.h fl_normal_from, the
/// emitters' batches and the device run the same function).
float standardNormal(float ua, float ub) noexcept;
}  // namespace detail

/// A stream of random numbers for one particle (or one emitter event), drawn four at a time.
/// Streams with different (id, step, stream) never overlap.
class Random {
 public:
  Random(std::uint64_t seed, std::uint32_t id, std::uint32_t step, std::uint32_t stream) noexcept
      : k0_(std::uint32_t(seed)),
        k1_(std::uint32_t(seed >> 32)),
        id_(id),
        step_(step),
        stream_(stream) {}

  std::uint32_t bits() noexcept {
    if (pos_ == 4) {
      block_ = Philox4x32::generate(id_, step_, stream_, counter_++, k0_, k1_);
      pos_ = 0;
    }
    return block_.v[pos_++];
  }
  /// Uniform in [0, 1).
  float uniform() noexcept { return uniformFloat(bits()); }
  /// Uniform in [lo, hi).
  float uniform(float lo, float hi) noexcept { return lo + (hi - lo) * uniform(); }
  /// Standard normal, by Box-Muller from two uniforms, in float arithmetic alone (no libm):
  /// the same bits on every CPU and on the device.
  float normal() noexcept {
    const float ua = uniform();
    return detail::standardNormal(ua, uniform());
  }

 private:
  std::uint32_t k0_, k1_, id_, step_, stream_;
  std::uint32_t counter_ = 0;
  int pos_ = 4;
  Philox4x32::Block block_{};
};

/// Stream numbers reserved by the SDK; actions use their index in the action list.
namespace stream {
inline constexpr std::uint32_t kEmission = 0xFFFF0000u;  ///< a newborn's attributes
inline constexpr std::uint32_t kEmitterEvent = 0xFFFF0001u;
inline constexpr std::uint32_t kPassThrough = 0xFFFF0002u;  ///< a Sink's once-per-particle pass
/// A death emitter's newborn counts: this plus the emitter's index in its group (< 65536).
inline constexpr std::uint32_t kDeathEmitter = 0xFFFE0000u;
}  // namespace stream

}  // namespace flurry
