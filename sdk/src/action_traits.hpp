// What the backends need to know about actions beyond running them.
#pragma once

#include "flurry/actions.hpp"

namespace flurry::detail {

/// A force an integrator can evaluate as an acceleration a(p, v, t) (see Integrator).
bool isForce(const Action& a);
/// A force with a closed-form step (constant acceleration, linear drag).
bool hasClosedForm(const Action& a);

/// What an action reads and writes of each particle it runs on: the attributes a group stores
/// for it (ActionList::attributes, their union), and the lanes a device's kernel loads and
/// stores for it (codegen.cpp; Move adds what its integration keeps up to date there).
struct AttributeAccess {
  AttributeSet reads, writes;
};
AttributeAccess attributeAccess(const Action& a);
/// Whether the action may change positions or velocities (it writes either; a Callback
/// always may): the pass's bounds of a block are taken again after it, on both backends.
bool movesParticles(const Action& a);

/// The kill code that marks particles whose position or velocity became NaN or infinite.
inline constexpr std::uint32_t kNonFiniteCode = 255;

}  // namespace flurry::detail
