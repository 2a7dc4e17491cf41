#pragma once
// Human-readable text for schemas and values, shared by error messages, `msim info` and the docs
// generator so all three describe a parameter the same way.
#include <string>
#include <string_view>

#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

// What a value must look like, as a noun phrase: "an integer >= 1", "a number in (0, 1]",
// "a vector of 2 or 3 numbers", "one of 'open', 'closed'".
std::string expectationText(const Schema& schema);

// Short type label for tables: "number > 0", "integer >= 1", "vector3", "string (open|closed)".
std::string typeLabel(const Schema& schema);

// A value for display: strings unquoted, numbers in shortest round-trip form, number arrays
// as "[0.1, 0.2]".
std::string valueText(const json& value);

// A value with its JSON type, for "got ..." in error messages: `string "abc"`, `number 3.5`.
std::string typedValueText(const json& value);

// Key paths: "domain" + "min" -> "domain.min"; "sources" + 1 -> "sources[1]".
std::string childPath(std::string_view parent, std::string_view key);
std::string indexPath(std::string_view parent, std::size_t index);

}  // namespace msim::scene
