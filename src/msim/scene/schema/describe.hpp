#pragma once
// Parameter listings generated from the schema: the `msim info` table of a resolved scene and the
// Markdown reference of every parameter for the docs.
#include <string>
#include <vector>

#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct ParamRow {
  std::string path;          // "sources[0].shape.radius"
  std::string value;         // resolved value as text
  std::string defaultValue;  // "required" for keys without a default
  std::string unit;          // SI unit, empty for dimensionless or non-numeric
  std::string description;
};

// One row per leaf parameter of a resolved scene (see resolve()), array items included; an empty
// array gets a single row so it stays visible.
std::vector<ParamRow> describe(const Schema& schema, const json& resolved);

// Rows as an aligned plain-text table with a header line.
std::string formatParamTable(const std::vector<ParamRow>& rows);

// Markdown table (key, type, default, unit, description) of every parameter the schema declares;
// array items appear as "name[].key" and variant fields say which "type" they belong to.
std::string markdownReference(const Schema& schema);

}  // namespace msim::scene
