#include "msim/scene/schema/schema_text.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "msim/scene/schema/key_suggestion.hpp"

namespace msim::scene {
namespace {

std::string number(double v) { return fmt::format("{}", v); }

// " >= 1", " in (0, 1]", or "" when unbounded.
std::string rangeSuffix(const Schema& s) {
  const auto& lo = s.lowerBound();
  const auto& hi = s.upperBound();
  if (lo && hi) {
    return fmt::format(" in {}{}, {}{}", lo->kind == Bound::Inclusive ? "[" : "(", number(lo->value),
                       number(hi->value), hi->kind == Bound::Inclusive ? "]" : ")");
  }
  if (lo) return fmt::format(" {} {}", lo->kind == Bound::Inclusive ? ">=" : ">", number(lo->value));
  if (hi) return fmt::format(" {} {}", hi->kind == Bound::Inclusive ? "<=" : "<", number(hi->value));
  return {};
}

std::string lengthsText(const std::vector<int>& lengths, std::string_view separator) {
  std::string out;
  for (std::size_t i = 0; i < lengths.size(); ++i) {
    if (i > 0) out += separator;
    out += std::to_string(lengths[i]);
  }
  return out;
}

std::vector<std::string> alternativeNames(const Schema& s) {
  std::vector<std::string> names;
  for (const auto& a : s.alternatives()) names.push_back(a.typeName);
  return names;
}

}  // namespace

std::string expectationText(const Schema& s) {
  switch (s.type()) {
    case SchemaType::Object: return "an object";
    case SchemaType::Array: return "an array";
    case SchemaType::Number: return "a number" + rangeSuffix(s);
    case SchemaType::Integer: return "an integer" + rangeSuffix(s);
    case SchemaType::Bool: return "a boolean";
    case SchemaType::String:
      return s.allowedStrings().empty() ? "a string" : "one of " + quotedList(s.allowedStrings());
    case SchemaType::Vector: {
      const std::string range = rangeSuffix(s);
      return "a vector of " + lengthsText(s.allowedLengths(), " or ") + " numbers" +
             (range.empty() ? "" : " (each" + range + ")");
    }
    case SchemaType::Variant: return "an object with \"type\" one of " + quotedList(alternativeNames(s));
  }
  return {};
}

std::string typeLabel(const Schema& s) {
  switch (s.type()) {
    case SchemaType::Object: return "object";
    case SchemaType::Array: return "array";
    case SchemaType::Number: return "number" + rangeSuffix(s);
    case SchemaType::Integer: return "integer" + rangeSuffix(s);
    case SchemaType::Bool: return "bool";
    case SchemaType::String: {
      std::string choices;
      for (const auto& c : s.allowedStrings()) choices += (choices.empty() ? "" : "|") + c;
      return choices.empty() ? "string" : "string (" + choices + ")";
    }
    case SchemaType::Vector: return "vector" + lengthsText(s.allowedLengths(), "|") + rangeSuffix(s);
    case SchemaType::Variant: return "variant";
  }
  return {};
}

std::string valueText(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) return number(v.get<double>());
  if (v.is_array() && std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_number(); })) {
    std::string out = "[";
    for (std::size_t i = 0; i < v.size(); ++i) out += (i > 0 ? ", " : "") + valueText(v[i]);
    return out + "]";
  }
  return v.dump();
}

std::string typedValueText(const json& v) {
  if (v.is_null()) return "null";
  if (v.is_boolean()) return std::string("boolean ") + (v.get<bool>() ? "true" : "false");
  if (v.is_number()) return "number " + valueText(v);
  if (v.is_string()) return "string " + v.dump();
  constexpr std::size_t kMaxShown = 60;  // a whole sub-object in an error line is noise
  std::string text = v.dump();
  if (text.size() > kMaxShown) text = text.substr(0, kMaxShown) + "...";
  return std::string(v.is_array() ? "array " : "object ") + text;
}

std::string childPath(std::string_view parent, std::string_view key) {
  return parent.empty() ? std::string(key) : std::string(parent) + "." + std::string(key);
}

std::string indexPath(std::string_view parent, std::size_t index) {
  return std::string(parent) + "[" + std::to_string(index) + "]";
}

}  // namespace msim::scene
