// Carrying an effect's emitters and action lists by an instance's transform.
#pragma once

#include "flurry/actions.hpp"
#include "flurry/emitter.hpp"
#include "flurry/transform.hpp"

namespace flurry::detail {

/// The emitter as seen in the world when its group stands at `t`.
Emitter transformEmitter(const Emitter& e, const Transform& t);
PrimeEmitter transformPrime(const PrimeEmitter& e, const Transform& t);
/// The action list with its geometry carried by `t` (see Transform for what follows).
ActionList transformActions(const ActionList& list, const Transform& t);

}  // namespace flurry::detail
