// What the backends need to know about actions beyond running them.
#pragma once

#include <cstdint>
#include <vector>

#include "flurry/actions.hpp"

namespace flurry::detail {

/// A force an integrator can evaluate as an acceleration a(p, v, t) (see Integrator).
bool isForce(const Action& a);
/// A force with a closed-form step (constant acceleration, linear drag).
bool hasClosedForm(const Action& a);

/// How an integrating Move (Explicit Euler, Verlet, RK4, Exact) takes what comes before it,
/// derived here once for both backends (the CPU's ActionPlan, the device's code generator):
/// the forces since the previous Move are evaluated by its integrator as one acceleration
/// (`gathered`, per action; `forcesOf`, per Move, in list order), and the Bounces since the
/// previous Move guard its step (`guardsOf`, per Move). A planar Bounce among them under
/// Exact, Verlet or RK4 bounces on the curve that Move takes (`curvedBy`: 1 + its index).
/// A force with no Move after it is its own update, as under semi-implicit Euler, which
/// gathers nothing. The vectors are resized and refilled, keeping their storage.
void planMoves(const ActionList& list, std::vector<std::uint8_t>& gathered,
               std::vector<std::vector<std::uint32_t>>& forcesOf,
               std::vector<std::vector<std::uint32_t>>& guardsOf,
               std::vector<std::uint32_t>& curvedBy);

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
