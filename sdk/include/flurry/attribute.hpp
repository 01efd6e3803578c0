// Particle attributes. A group stores each attribute component as its own array
// (structure-of-arrays), and stores only the attributes some action, emitter, renderer or
// exporter of the scene reads: the others are never allocated and never touched.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string_view>

namespace flurry {

enum class Attribute : std::uint8_t {
  Position,      ///< x, y, z (always stored)
  Velocity,      ///< vx, vy, vz
  Color,         ///< r, g, b, a
  Size,          ///< radius
  Mass,          ///<
  Age,           ///< seconds since birth
  Lifetime,      ///< seconds; KillOld kills when age > lifetime
  Id,            ///< unique per group, never reused (always stored); stored as uint32
  PrevPosition,  ///< position before the last Move
  Up,            ///< orientation: up vector
  RotVelocity,   ///< angular velocity
  Charge,        ///< electric charge, for the Lorentz force
  Visible,       ///< 1 visible, 0 hidden by a blocker; stored as uint32
  UserData,      ///< one free float for callbacks
  PositionB,     ///< a second, rest position (CopyVertexB, Restore)
  VelocityB,     ///< a second velocity (CopyVertexB)
  BirthColor,    ///< r, g, b, a at birth (ColorOverLife in Multiply mode scales it)
  BirthSize,     ///< radius at birth (SizeOverLife in Multiply mode scales it)
  Count
};

/// Number of 32-bit components of an attribute.
constexpr int componentCount(Attribute a) {
  switch (a) {
    case Attribute::Position:
    case Attribute::Velocity:
    case Attribute::PrevPosition:
    case Attribute::Up:
    case Attribute::RotVelocity:
    case Attribute::PositionB:
    case Attribute::VelocityB:
      return 3;
    case Attribute::Color:
    case Attribute::BirthColor:
      return 4;
    default:
      return 1;
  }
}

std::string_view attributeName(Attribute a);

/// A set of attributes (a bit mask).
class AttributeSet {
 public:
  constexpr AttributeSet() = default;
  constexpr AttributeSet(std::initializer_list<Attribute> list) {
    for (Attribute a : list) insert(a);
  }
  constexpr bool has(Attribute a) const { return bits_ & bit(a); }
  constexpr AttributeSet& insert(Attribute a) {
    bits_ |= bit(a);
    return *this;
  }
  constexpr AttributeSet& insert(AttributeSet s) {
    bits_ |= s.bits_;
    return *this;
  }
  constexpr bool contains(AttributeSet s) const { return (bits_ & s.bits_) == s.bits_; }
  /// Every attribute.
  static constexpr AttributeSet all() {
    AttributeSet s;
    s.bits_ = (1u << unsigned(Attribute::Count)) - 1u;
    return s;
  }
  constexpr std::uint32_t bits() const { return bits_; }
  friend constexpr AttributeSet operator|(AttributeSet a, AttributeSet b) { return a.insert(b); }
  friend constexpr bool operator==(AttributeSet, AttributeSet) = default;
  /// Bytes per particle to store these attributes.
  constexpr int bytesPerParticle() const {
    int n = 0;
    for (int i = 0; i < int(Attribute::Count); ++i)
      if (has(Attribute(i))) n += 4 * componentCount(Attribute(i));
    return n;
  }

 private:
  static constexpr std::uint32_t bit(Attribute a) { return 1u << unsigned(a); }
  std::uint32_t bits_ = 0;
};

}  // namespace flurry
