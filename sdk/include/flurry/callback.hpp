// A user action written once: FLURRY_CALLBACK's body is C++ for the CPU backend and, the same
// text, OpenCL C for a device. The body names the particle's attributes by the variables
// below (the OpenCL kernel's own names), calls the OpenCL C math builtins listed in
// flurry::callback_builtins, and ends early with `break`:
//
//   g.setActions({Gravity{}, FLURRY_CALLBACK(
//                     user += dt;
//                     if (py > 2.0f) vx += 0.5f;
//                 ), Move{}});
//
// What the body may contain is what both languages read alike: float arithmetic with float
// literals (2.0f: a double literal needs a device with doubles), the variables, if/else,
// loops that end whatever the values (the device may run the body on zeros past the live
// particles), locals of float, int or uint, and the builtins. Not `return` (it would leave the
// device's kernel), not preprocessor lines, not comments that matter (the preprocessor drops
// them before the body becomes a string). A body the device's compiler refuses is reported
// when the list first runs there, with the compiler's log.
#pragma once

#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <utility>

#include "flurry/actions.hpp"
#include "flurry/attribute.hpp"
#include "flurry/group.hpp"

namespace flurry {

/// The variables a callback body calls each attribute's components by, indexed by Attribute:
/// the same names on the CPU (FLURRY_CALLBACK's references) and on the device (the fused
/// kernel's locals). BirthColor and BirthSize are not in Particle: a body that uses them
/// runs on the device only (Callback::opencl).
inline constexpr std::array<std::array<std::string_view, 4>, std::size_t(Attribute::Count)>
    kCallbackVariables = {{
        {"px", "py", "pz"},
        {"vx", "vy", "vz"},
        {"r", "g", "b", "a"},
        {"size"},
        {"mass"},
        {"age"},
        {"life"},
        {"id"},
        {"prevx", "prevy", "prevz"},
        {"upx", "upy", "upz"},
        {"rotx", "roty", "rotz"},
        {"charge"},
        {"vis"},
        {"user"},
        {"pbx", "pby", "pbz"},
        {"vbx", "vby", "vbz"},
        {"birthr", "birthg", "birthb", "birtha"},
        {"birthsize"},
    }};

namespace detail {
constexpr bool isIdentifierChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}
}  // namespace detail

/// Whether `word` stands in `text` as a whole identifier (not inside a longer name or a
/// number's suffix).
constexpr bool usesIdentifier(std::string_view text, std::string_view word) {
  for (std::size_t at = text.find(word); at != std::string_view::npos;
       at = text.find(word, at + 1)) {
    const bool before = at > 0 && detail::isIdentifierChar(text[at - 1]);
    const std::size_t end = at + word.size();
    const bool after = end < text.size() && detail::isIdentifierChar(text[end]);
    if (!before && !after) return true;
  }
  return false;
}

/// The attributes whose variables (kCallbackVariables) stand in `body` as whole identifiers:
/// what a callback written with them reads and writes, so what its group must store.
constexpr AttributeSet attributesUsedBy(std::string_view body) {
  AttributeSet used;
  for (std::size_t k = 0; k < kCallbackVariables.size(); ++k)
    for (std::string_view name : kCallbackVariables[k])
      if (!name.empty() && usesIdentifier(body, name)) used.insert(Attribute(k));
  return used;
}

/// A Callback whose body is written once (FLURRY_CALLBACK): `function` runs it on the CPU,
/// `body` (Callback::opencl) on a device, and it stores attributesUsedBy(body).
inline Callback sharedCallback(std::string_view body,
                               std::function<void(Particle&, const CallbackContext&)> function) {
  return Callback{std::move(function), attributesUsedBy(body), std::string(body)};
}

/// OpenCL C's scalar math builtins for FLURRY_CALLBACK's body on the CPU: the float overloads
/// of <cmath>, and OpenCL's own (clamp, mix, step, smoothstep, sign, min, max, radians,
/// degrees, rsqrt) with OpenCL's definitions; min, max and clamp on int and uint as OpenCL
/// has them, abs on integers only (fabs for floats, as in OpenCL). The body sees exactly
/// these names (declared in its scope); a builtin not here may find the C library's double
/// function on the CPU: stick to these. Correctly rounded operations (+ - * /, sqrt, fmin,
/// fmax, fabs, floor, ...) agree to the bit with the device; sin, exp, pow and their kind
/// agree within the device's error bounds.
namespace callback_builtins {
using uint = std::uint32_t;
using std::acos, std::asin, std::atan, std::atan2, std::cbrt, std::ceil, std::copysign, std::cos,
    std::cosh, std::exp, std::exp2, std::fabs, std::floor, std::fma, std::fmax, std::fmin,
    std::fmod, std::hypot, std::log, std::log10, std::log2, std::pow, std::round, std::sin,
    std::sinh, std::sqrt, std::tan, std::tanh, std::trunc;
// On float, int and uint, as OpenCL has them (both arguments of one type).
template <class T>
concept OpenCLScalar = std::same_as<T, float> || std::same_as<T, int> || std::same_as<T, uint>;
template <OpenCLScalar T>
inline T min(T x, T y) {
  return y < x ? y : x;
}
template <OpenCLScalar T>
inline T max(T x, T y) {
  return x < y ? y : x;
}
template <OpenCLScalar T>
inline T clamp(T x, T lo, T hi) {
  return min(max(x, lo), hi);
}
inline float clamp(float x, float lo, float hi) {  // OpenCL's, for floats
  return fmin(fmax(x, lo), hi);
}
inline float mix(float x, float y, float a) {
  return x + (y - x) * a;
}
inline float step(float edge, float x) {
  return x < edge ? 0.0f : 1.0f;
}
inline float smoothstep(float e0, float e1, float x) {
  const float t = clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}
inline float sign(float x) {
  if (std::isnan(x)) return 0.0f;
  return x > 0.0f ? 1.0f : (x < 0.0f ? -1.0f : copysign(0.0f, x));
}
inline uint abs(int x) {
  return x < 0 ? 0u - uint(x) : uint(x);
}
inline uint abs(uint x) {
  return x;
}
float abs(float) = delete;  // OpenCL's abs is for integers: fabs
inline float radians(float degrees) {
  return degrees * 0.0174532925199432957692f;
}
inline float degrees(float radians) {
  return radians * 57.295779513082320876798f;
}
inline float rsqrt(float x) {
  return 1.0f / std::sqrt(x);
}
inline constexpr float M_PI_F = 3.14159265358979323846f;
}  // namespace callback_builtins

}  // namespace flurry

// The particle's attributes as kCallbackVariables names them, bound to a Particle; dt and
// time as the device's kernel has them.
#define FLURRY_DETAIL_CALLBACK_VARIABLES(P, C)                                             \
  [[maybe_unused]] float &px = P.position.x, &py = P.position.y, &pz = P.position.z;       \
  [[maybe_unused]] float &vx = P.velocity.x, &vy = P.velocity.y, &vz = P.velocity.z;       \
  [[maybe_unused]] float &r = P.color.r, &g = P.color.g, &b = P.color.b, &a = P.color.a;   \
  [[maybe_unused]] float &size = P.size, &mass = P.mass, &age = P.age, &life = P.lifetime; \
  [[maybe_unused]] const std::uint32_t id = P.id;                                          \
  [[maybe_unused]] float &prevx = P.prevPosition.x, &prevy = P.prevPosition.y,             \
                         &prevz = P.prevPosition.z;                                        \
  [[maybe_unused]] float &upx = P.up.x, &upy = P.up.y, &upz = P.up.z;                      \
  [[maybe_unused]] float &rotx = P.rotVelocity.x, &roty = P.rotVelocity.y,                 \
                         &rotz = P.rotVelocity.z;                                          \
  [[maybe_unused]] float &charge = P.charge, &user = P.userData;                           \
  [[maybe_unused]] std::uint32_t vis = P.visible ? 1u : 0u; /* a uint, as on the device */ \
  [[maybe_unused]] float &pbx = P.positionB.x, &pby = P.positionB.y, &pbz = P.positionB.z; \
  [[maybe_unused]] float &vbx = P.velocityB.x, &vby = P.velocityB.y, &vbz = P.velocityB.z; \
  [[maybe_unused]] const float dt = C.dt;                                                  \
  [[maybe_unused]] const double time = C.time;

// callback_builtins' names, declared in the body's scope so that they hide any other
// function of that name the surrounding code sees.
#define FLURRY_DETAIL_CALLBACK_BUILTINS                                           \
  using ::flurry::callback_builtins::uint;                                        \
  using ::flurry::callback_builtins::acos, ::flurry::callback_builtins::asin,     \
      ::flurry::callback_builtins::atan, ::flurry::callback_builtins::atan2,      \
      ::flurry::callback_builtins::cbrt, ::flurry::callback_builtins::ceil,       \
      ::flurry::callback_builtins::copysign, ::flurry::callback_builtins::cos,    \
      ::flurry::callback_builtins::cosh, ::flurry::callback_builtins::exp,        \
      ::flurry::callback_builtins::exp2, ::flurry::callback_builtins::fabs,       \
      ::flurry::callback_builtins::floor, ::flurry::callback_builtins::fma,       \
      ::flurry::callback_builtins::fmax, ::flurry::callback_builtins::fmin,       \
      ::flurry::callback_builtins::fmod, ::flurry::callback_builtins::hypot,      \
      ::flurry::callback_builtins::log, ::flurry::callback_builtins::log10,       \
      ::flurry::callback_builtins::log2, ::flurry::callback_builtins::pow,        \
      ::flurry::callback_builtins::round, ::flurry::callback_builtins::sin,       \
      ::flurry::callback_builtins::sinh, ::flurry::callback_builtins::sqrt,       \
      ::flurry::callback_builtins::tan, ::flurry::callback_builtins::tanh,        \
      ::flurry::callback_builtins::trunc, ::flurry::callback_builtins::clamp,     \
      ::flurry::callback_builtins::mix, ::flurry::callback_builtins::step,        \
      ::flurry::callback_builtins::smoothstep, ::flurry::callback_builtins::sign, \
      ::flurry::callback_builtins::min, ::flurry::callback_builtins::max,         \
      ::flurry::callback_builtins::abs, ::flurry::callback_builtins::radians,     \
      ::flurry::callback_builtins::degrees, ::flurry::callback_builtins::rsqrt,   \
      ::flurry::callback_builtins::M_PI_F;                                        \
  (void)M_PI_F; /* a body need not use it */

// The body's names (r, g, size, ...) may shadow the caller's locals on purpose: no -Wshadow
// warning for them.
#if defined(__clang__)
#define FLURRY_DETAIL_NO_SHADOW_BEGIN \
  _Pragma("clang diagnostic push") _Pragma("clang diagnostic ignored \"-Wshadow-all\"")
#define FLURRY_DETAIL_NO_SHADOW_END _Pragma("clang diagnostic pop")
#elif defined(__GNUC__)
#define FLURRY_DETAIL_NO_SHADOW_BEGIN \
  _Pragma("GCC diagnostic push") _Pragma("GCC diagnostic ignored \"-Wshadow\"")
#define FLURRY_DETAIL_NO_SHADOW_END _Pragma("GCC diagnostic pop")
#else
#define FLURRY_DETAIL_NO_SHADOW_BEGIN
#define FLURRY_DETAIL_NO_SHADOW_END
#endif

/// A Callback action whose body is written once, as statements in the shared subset (see the
/// top of this file): the CPU runs them compiled as C++, a device as OpenCL C.
#define FLURRY_CALLBACK(...)                                                                \
  ::flurry::sharedCallback(#__VA_ARGS__, [](::flurry::Particle& flurry_particle_,           \
                                            const ::flurry::CallbackContext& flurry_ctx_) { \
    static_assert(!::flurry::usesIdentifier(#__VA_ARGS__, "return"),                        \
                  "FLURRY_CALLBACK: 'return' would leave the device's kernel; use break");  \
    FLURRY_DETAIL_NO_SHADOW_BEGIN                                                           \
    FLURRY_DETAIL_CALLBACK_VARIABLES(flurry_particle_, flurry_ctx_)                         \
    FLURRY_DETAIL_NO_SHADOW_END                                                             \
    FLURRY_DETAIL_CALLBACK_BUILTINS                                                         \
    do {                                                                                    \
      __VA_ARGS__                                                                           \
    } while (0);                                                                            \
    flurry_particle_.visible = vis != 0u;                                                   \
  })
