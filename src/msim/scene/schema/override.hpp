#pragma once
// Command-line overrides of scene parameters: `msim run scene.json --set domain.resolution=64`.
#include <string_view>

#include <nlohmann/json.hpp>

namespace msim::scene {

// Applies "key.path=value" to the (unresolved) scene document. The path uses dots for object keys
// and [index] for array items ("sources[0].shape.radius"); missing object keys are created so a
// parameter left at its default can still be overridden, and resolve() later rejects misspelled
// keys. The value is parsed as JSON when it parses ("64", "[0,1,0]", "true") and is taken as a
// plain string otherwise ("closed"). Throws InputError for a malformed assignment or a path that
// cannot exist: an index out of range, or a key or index applied to a value of the wrong kind.
void applyOverride(nlohmann::json& scene, std::string_view assignment);

}  // namespace msim::scene
