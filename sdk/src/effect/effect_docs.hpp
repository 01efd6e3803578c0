// Files generated from the action and emitter descriptors (descriptors.hpp), printed by
// tests/effect/flurry_effect_docs and checked against the committed copies. Internal.
#pragma once

#include <string>

namespace flurry::detail {

/// docs/effect.schema.json: a JSON Schema (draft 2020-12) of effect files, for editors.
std::string effectSchema();
/// docs/effect-reference.md: every action's and emitter part's fields, as Markdown tables.
std::string effectReference();
/// tests/fuzz/effect.dict: the libFuzzer dictionary of field names, type names and tokens.
std::string fuzzDictionary();

}  // namespace flurry::detail
