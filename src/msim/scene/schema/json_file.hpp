#pragma once
// Reading scene files from disk with errors a user can act on (file:line:column).
#include <filesystem>

#include <nlohmann/json.hpp>

namespace msim::scene {

// Parses a JSON file; // and /* */ comments are allowed so scenes can explain themselves.
// Throws InputError "scene file 'X' not found" or "X:LINE:COL: malformed JSON: <what>".
nlohmann::json loadJsonFile(const std::filesystem::path& path);

}  // namespace msim::scene
