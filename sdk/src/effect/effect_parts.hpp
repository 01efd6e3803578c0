// The effect loader's readers for single parts of an effect (an action list, an emitter), for
// code that builds those parts by name and field rather than from a whole file: the C API
// (bindings/c) collects the fields a caller sets into JSON and reads it here, so that the
// loader stays the one place that knows each action's fields, defaults and validation, and
// errors name the field exactly as they do for an effect file. Internal: not installed.
#pragma once

#include <string>
#include <string_view>

#include "flurry/actions.hpp"
#include "flurry/effect.hpp"
#include "flurry/emitter.hpp"

namespace flurry::detail {

/// JSON paths in errors: join("groups[0]", "rate") is "groups[0].rate", index("groups", 2)
/// is "groups[2]".
inline std::string join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}
inline std::string index(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

/// Throws EffectError at `path`.type unless `type` names an action an effect file can hold
/// (with the nearest name as a suggestion), e.g. "actions[2].type: unknown action ...".
void checkEffectActionType(const std::string& type, const std::string& fileName,
                           const std::string& path);

/// Reads `actions`, the JSON text of an array of action objects (a group's "actions"), as
/// the loader reads a group's actions; `path` names the array ("actions"), so an error
/// reads "FILE: actions[1].restitution: why" (just "actions[1]...: why" for an empty
/// fileName). Throws EffectError.
ActionList parseEffectActions(std::string_view actions, const std::string& fileName,
                              const std::string& path, const EffectLoadOptions& options = {});

/// Reads and validates `emitter`, the JSON text of one emitter object, as the loader reads
/// a group's emitters[i]; `path` is its JSON path. Throws EffectError.
Emitter parseEffectEmitter(std::string_view emitter, const std::string& fileName,
                           const std::string& path, const EffectLoadOptions& options = {});

/// Reads and validates `deathEmitter`, the JSON text of one death emitter object, as the
/// loader reads a group's deathEmitters[i] (its source is not looked up: the context does
/// that when it steps); `path` is its JSON path. Throws EffectError.
DeathEmitter parseEffectDeathEmitter(std::string_view deathEmitter, const std::string& fileName,
                                     const std::string& path,
                                     const EffectLoadOptions& options = {});

}  // namespace flurry::detail
