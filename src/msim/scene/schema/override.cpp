#include "msim/scene/schema/override.hpp"

#include <algorithm>
#include <charconv>
#include <string>
#include <variant>
#include <vector>

#include "msim/core/error.hpp"
#include "msim/scene/schema/schema_text.hpp"

namespace msim::scene {
namespace {

using PathStep = std::variant<std::string, std::size_t>;  // object key or array index

class OverrideParser {
 public:
  explicit OverrideParser(std::string_view assignment) : assignment_(assignment) {}

  [[noreturn]] void fail(const std::string& why) const {
    throw InputError("--set '" + std::string(assignment_) + "': " + why);
  }

  // path := step (('.' key) | ('[' index ']'))*, where the first step is a key or an index.
  std::vector<PathStep> parsePath(std::string_view path) const {
    if (path.empty()) fail("empty key path");
    std::vector<PathStep> steps;
    std::size_t i = 0;
    while (true) {
      if (path[i] == '[') {
        const std::size_t close = path.find(']', i);
        if (close == std::string_view::npos) fail("missing ']' in key path");
        const std::string_view digits = path.substr(i + 1, close - i - 1);
        std::size_t index = 0;
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
        if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size())
          fail("array index '" + std::string(digits) + "' is not a non-negative integer");
        steps.emplace_back(index);
        i = close + 1;
      } else {
        const std::size_t end = std::min(path.find_first_of(".[", i), path.size());
        if (end == i) fail("empty key in key path");
        steps.emplace_back(std::string(path.substr(i, end - i)));
        i = end;
      }
      if (i == path.size()) return steps;
      if (path[i] == '.') {
        ++i;
        if (i == path.size() || path[i] == '.' || path[i] == '[') fail("empty key in key path");
      } else if (path[i] != '[') {
        fail("expected '.' or '[' after ']' in key path");
      }
    }
  }

  nlohmann::json& walk(nlohmann::json& root, const std::vector<PathStep>& steps) const {
    nlohmann::json* at = &root;
    std::string where;
    for (const auto& step : steps) {
      if (const auto* key = std::get_if<std::string>(&step)) {
        if (at->is_null()) *at = nlohmann::json::object();
        if (!at->is_object()) {
          const std::string name = where.empty() ? std::string("the scene") : "'" + where + "'";
          fail(name + " is " + typedValueText(*at) + ", not an object");
        }
        where = childPath(where, *key);
        at = &(*at)[*key];
      } else {
        const std::size_t index = std::get<std::size_t>(step);
        if (!at->is_array())
          fail("'" + where + "' is " + (at->is_null() ? "not set in the scene" : typedValueText(*at) + ", not an array"));
        if (index >= at->size())
          fail("index " + std::to_string(index) + " is out of range: '" + where + "' has " + std::to_string(at->size()) +
               " items");
        where = indexPath(where, index);
        at = &(*at)[index];
      }
    }
    return *at;
  }

 private:
  std::string_view assignment_;
};

}  // namespace

void applyOverride(nlohmann::json& scene, std::string_view assignment) {
  const OverrideParser parser(assignment);
  const std::size_t eq = assignment.find('=');
  if (eq == std::string_view::npos) parser.fail("expected key.path=value");
  const std::string valueText(assignment.substr(eq + 1));
  nlohmann::json value = nlohmann::json::parse(valueText, nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) value = valueText;
  parser.walk(scene, parser.parsePath(assignment.substr(0, eq))) = std::move(value);
}

}  // namespace msim::scene
