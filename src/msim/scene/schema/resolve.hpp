#pragma once
// resolve: check a parsed scene file against its schema and fill in every default, so the
// simulation code reads a complete, valid document and never has to guess.
#include <string_view>

#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

// Returns `input` with defaults filled in (Number -> double, Integer -> integer, Variant keeps its
// "type" key). Throws InputError on the first problem; the message starts with "<sourceName>: "
// and names the full key path (e.g. "sources[1].rate"): unknown keys (with the closest valid key
// suggested), wrong types, values out of range, missing required keys, unknown variant types.
json resolve(const Schema& schema, const json& input, std::string_view sourceName);

}  // namespace msim::scene
