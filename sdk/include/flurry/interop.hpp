// Interop: the live particles of a group packed as vertex or instance data for a game's own
// renderer, in the layout it asks for. GL-free: part of flurry::flurry, no window, no GPU.
//
//   flurry::PackLayout layout = flurry::PackLayout::interleaved(
//       {{flurry::Attribute::Position, flurry::PackFormat::Float32},
//        {flurry::Attribute::Color, flurry::PackFormat::UNorm8}});  // 16 bytes a particle
//   group.require(layout.attributes());                              // before stepping
//   ...
//   std::vector<std::byte> bytes(group.size() * layout.stride);
//   std::size_t n = flurry::packParticles(group, layout, bytes);    // then glBufferData, draw n
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "flurry/attribute.hpp"
#include "flurry/domain.hpp"
#include "flurry/group.hpp"

namespace flurry {

/// How one component is stored in the packed record.
enum class PackFormat : std::uint8_t {
  Float32,  ///< 4 bytes, IEEE float (Id and Visible converted to float)
  UNorm8,   ///< 1 byte, round(clamp(v, 0, 1) * 255): colors for GL_UNSIGNED_BYTE normalized
  UInt32,   ///< 4 bytes, only for Id and Visible
};

/// Bytes one component takes in `format`.
constexpr std::uint32_t packedBytes(PackFormat format) {
  return format == PackFormat::UNorm8 ? 1u : 4u;
}

/// One attribute (all of its componentCount() components, consecutive) in the record.
struct PackField {
  Attribute attribute = Attribute::Position;
  PackFormat format = PackFormat::Float32;
  std::uint32_t offset = 0;  ///< bytes from the start of a particle's record
};

/// A particle's record: the fields and the bytes from one particle's record to the next.
struct PackLayout {
  std::vector<PackField> fields;
  std::uint32_t stride = 0;

  /// The fields back to back in the given order, each 4-byte field 4-byte aligned, the
  /// stride rounded up to 4.
  static PackLayout interleaved(std::initializer_list<std::pair<Attribute, PackFormat>> fields);
  /// Flurry's own instance layout (what flurry::render draws): position xyz, size (radius),
  /// color rgba, all Float32: 32 bytes.
  static PackLayout instances();
  /// What the fields read: pass to Group::require() before stepping. Visible is left out (a
  /// blocker action stores it; a renderer only honours it).
  AttributeSet attributes() const;
};

/// Which particles are packed, and in what order.
struct PackOptions {
  /// Leave out particles whose Visible attribute is 0 (hidden by a blocker), when stored.
  bool skipHidden = true;
  /// Leave out particles whose position lies inside any of these regions (render-time
  /// blockers: the particles are still simulated).
  std::span<const Domain> blockers;
  /// Order the particles from the farthest to the nearest to this eye, as alpha blending
  /// without a depth buffer needs. Empty: the group's own order.
  std::optional<Vec3> sortFromEye;
};

/// Packs the group's live particles that `options` keeps into `out`, `layout.stride` bytes
/// each, and returns how many. Attributes the group does not store are written as
/// Particle's defaults (white, radius 0.05, visible). Throws InvalidArgument naming the bad
/// field ("layout.fields[1].offset") if the layout is inconsistent, and if `out` is shorter
/// than group.size() * layout.stride ("out").
std::size_t packParticles(const Group& group, const PackLayout& layout, std::span<std::byte> out,
                          const PackOptions& options = {});

/// The live particles' trails (Group::setTrail) as ribbons for a renderer, into `out`
/// (cleared; its storage is reused, so a game calling it every frame allocates nothing
/// once it has grown): one strand per particle with two points or more, newest first. Each
/// point's radius is the group's TrailOptions::width (0: the particle's size) narrowing to
/// `taper` times it at the oldest point, and its colour the particle's, its alpha fading to
/// `fade` times the particle's there (linearly along the points). Particles `options` leaves
/// out (hidden, or inside a blocker at their own position) give none; sortFromEye is not
/// used. Returns the number of strands; a group without a trail gives none.
std::size_t trailStrands(const Group& group, Strands& out, const PackOptions& options = {});
/// Same, into a vector sized to exactly the packed particles.
std::vector<std::byte> packParticles(const Group& group, const PackLayout& layout,
                                     const PackOptions& options = {});

}  // namespace flurry
