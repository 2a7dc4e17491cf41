#pragma once
// "Did you mean ...?" for misspelled scene keys and choice values.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace msim::scene {

// Optimal-string-alignment (restricted Damerau-Levenshtein) distance: insertions, deletions,
// substitutions and swaps of adjacent characters each cost 1, so "resolutoin" is 1 from "resolution".
std::size_t editDistance(std::string_view a, std::string_view b);

// The candidate closest to `word`, if it is close enough to be a plausible typo (distance at most
// a third of the word's length, and at least 1 allowed); ties go to the earliest candidate.
std::optional<std::string> closestMatch(std::string_view word, const std::vector<std::string>& candidates);

// "'a', 'b', 'c'": candidates quoted and comma-separated, for error messages.
std::string quotedList(const std::vector<std::string>& words);

}  // namespace msim::scene
