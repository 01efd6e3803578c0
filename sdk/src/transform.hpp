// Carrying an effect's emitters and action lists by an instance's transform.
#pragma once

#include "flurry/actions.hpp"
#include "flurry/emitter.hpp"
#include "flurry/transform.hpp"

namespace flurry::detail {

/// The emitter as seen in the world when its group stands at `t`.
Emitter transformEmitter(const Emitter& e, const Transform& t);
PrimeEmitter transformPrime(const PrimeEmitter& e, const Transform& t);
/// The same, in place: e (a copy of the frame's emitter, reusing the storage of an earlier
/// image) becomes its image. Allocates nothing unless a domain is a mesh or a union, or a
/// prime emitter's child has `next` levels (each carried into a new copy).
void carryEmitter(Emitter& e, const Transform& t);
void carryPrime(PrimeEmitter& e, const Transform& t);
/// The action list with its geometry carried by `t` (see Transform for what follows).
ActionList transformActions(const ActionList& list, const Transform& t);
/// Rewrites `world`, an image of `local` under another transform, as its image under `t`,
/// in place: the same values as transformActions(local, t) without an allocation (unless a
/// domain is a mesh or a union). Returns false, changing nothing, when `world` does not hold
/// the same kinds of actions as `local`. Throws like transformActions, with `world` then
/// partly rewritten.
bool placeActions(ActionList& world, const ActionList& local, const Transform& t);

}  // namespace flurry::detail
