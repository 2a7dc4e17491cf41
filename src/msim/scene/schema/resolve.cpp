#include "msim/scene/schema/resolve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "msim/core/error.hpp"
#include "msim/scene/schema/key_suggestion.hpp"
#include "msim/scene/schema/schema_text.hpp"

namespace msim::scene {
namespace {

bool withinBound(double v, const std::optional<NumericBound>& lo, const std::optional<NumericBound>& hi) {
  if (lo && (lo->kind == Bound::Inclusive ? v < lo->value : v <= lo->value)) return false;
  if (hi && (hi->kind == Bound::Inclusive ? v > hi->value : v >= hi->value)) return false;
  return true;
}

bool isIntegral(const json& v) {
  // Integers are read as long long: larger unsigned ones do not fit.
  if (v.is_number_unsigned()) return v.get<std::uint64_t>() <= std::uint64_t(std::numeric_limits<long long>::max());
  if (v.is_number_integer()) return true;
  // 128.0 is an integer to a person editing JSON; accept it while it converts exactly (|v| <= 2^53).
  if (!v.is_number_float()) return false;
  const double d = v.get<double>();
  return std::isfinite(d) && std::floor(d) == d && std::abs(d) <= 9007199254740992.0;
}

class Resolver {
 public:
  explicit Resolver(std::string_view source) : source_(source) {}

  json node(const Schema& s, const json& v, const std::string& path) const {
    switch (s.type()) {
      case SchemaType::Object: return object(s, v, path, nullptr);
      case SchemaType::Array: return array(s, v, path);
      case SchemaType::Number: return number(s, v, path);
      case SchemaType::Integer: return integer(s, v, path);
      case SchemaType::Bool:
        if (!v.is_boolean()) wrongType(s, v, path);
        return v;
      case SchemaType::String: return string(s, v, path);
      case SchemaType::Vector: return vector(s, v, path);
      case SchemaType::Variant: return variant(s, v, path);
    }
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& message) const { throw InputError(std::string(source_) + ": " + message); }

  [[noreturn]] void wrongType(const Schema& s, const json& v, const std::string& path) const {
    if (path.empty()) fail("the scene must be " + expectationText(s) + ", got " + typedValueText(v));
    fail("key '" + path + "' expected " + expectationText(s) + ", got " + typedValueText(v));
  }

  void checkRange(const Schema& s, const json& v, const std::string& path) const {
    if (!withinBound(v.get<double>(), s.lowerBound(), s.upperBound()))
      fail("key '" + path + "' = " + valueText(v) + " is out of range: expected " + expectationText(s));
  }

  // `typeKey` is the variant's selector key: present in the input but not among the fields.
  json object(const Schema& s, const json& v, const std::string& path, const char* typeKey) const {
    if (!v.is_object()) wrongType(s, v, path);
    for (const auto& [key, value] : v.items()) {
      if (s.findField(key) || (typeKey && key == typeKey)) continue;
      std::vector<std::string> valid;
      if (typeKey) valid.push_back(typeKey);
      for (const auto& f : s.fields()) valid.push_back(f.name);
      const auto suggestion = closestMatch(key, valid);
      fail("unknown key '" + childPath(path, key) + "'; " +
           (suggestion ? "did you mean '" + *suggestion + "'?" : "valid keys are " + quotedList(valid)));
    }
    json out = json::object();
    for (const auto& f : s.fields()) {
      const std::string fieldPath = childPath(path, f.name);
      const Schema& fs = *f.schema;
      if (v.contains(f.name)) {
        out[f.name] = node(fs, v[f.name], fieldPath);
      } else if (fs.isRequired()) {
        fail("missing required key '" + fieldPath + "' (" + expectationText(fs) +
             (fs.description().empty() ? "" : ": " + fs.description()) + ")");
      } else if (fs.defaultJson()) {
        out[f.name] = node(fs, *fs.defaultJson(), fieldPath);
      } else if (fs.type() == SchemaType::Object) {
        out[f.name] = node(fs, json::object(), fieldPath);
      }
    }
    return out;
  }

  json array(const Schema& s, const json& v, const std::string& path) const {
    if (!v.is_array()) wrongType(s, v, path);
    const int n = static_cast<int>(v.size());
    if (n < s.minItems() || (s.maxItems() >= 0 && n > s.maxItems())) {
      const std::string limit = s.maxItems() < 0 ? "at least " + std::to_string(s.minItems())
                                : s.minItems() == s.maxItems()
                                    ? "exactly " + std::to_string(s.minItems())
                                    : "between " + std::to_string(s.minItems()) + " and " + std::to_string(s.maxItems());
      fail("key '" + path + "' has " + std::to_string(n) + " items; expected " + limit);
    }
    json out = json::array();
    for (std::size_t i = 0; i < v.size(); ++i) out.push_back(node(s.itemSchema(), v[i], indexPath(path, i)));
    return out;
  }

  json number(const Schema& s, const json& v, const std::string& path) const {
    if (!v.is_number()) wrongType(s, v, path);
    checkRange(s, v, path);
    return v.get<double>();
  }

  json integer(const Schema& s, const json& v, const std::string& path) const {
    if (!isIntegral(v)) wrongType(s, v, path);
    checkRange(s, v, path);
    return v.is_number_integer() ? v.get<long long>() : static_cast<long long>(v.get<double>());
  }

  json string(const Schema& s, const json& v, const std::string& path) const {
    if (!v.is_string()) wrongType(s, v, path);
    const auto& choices = s.allowedStrings();
    const std::string text = v.get<std::string>();
    if (!choices.empty() && std::find(choices.begin(), choices.end(), text) == choices.end()) {
      const auto suggestion = closestMatch(text, choices);
      fail("key '" + path + "' expected " + expectationText(s) + ", got " + typedValueText(v) +
           (suggestion ? "; did you mean '" + *suggestion + "'?" : ""));
    }
    return v;
  }

  json vector(const Schema& s, const json& v, const std::string& path) const {
    if (!v.is_array()) wrongType(s, v, path);
    const auto& lengths = s.allowedLengths();
    if (std::find(lengths.begin(), lengths.end(), static_cast<int>(v.size())) == lengths.end()) wrongType(s, v, path);
    json out = json::array();
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_number()) wrongType(s, v, path);
      checkRange(s, v[i], indexPath(path, i));
      out.push_back(v[i].get<double>());
    }
    return out;
  }

  json variant(const Schema& s, const json& v, const std::string& path) const {
    if (!v.is_object()) wrongType(s, v, path);
    std::vector<std::string> names;
    for (const auto& a : s.alternatives()) names.push_back(a.typeName);
    const std::string typePath = childPath(path, kVariantTypeKey);
    if (!v.contains(kVariantTypeKey)) fail("missing required key '" + typePath + "' (one of " + quotedList(names) + ")");
    const json& typeValue = v[kVariantTypeKey];
    const SchemaAlternative* alt = typeValue.is_string() ? s.findAlternative(typeValue.get<std::string>()) : nullptr;
    if (!alt) {
      const auto suggestion = typeValue.is_string() ? closestMatch(typeValue.get<std::string>(), names) : std::nullopt;
      fail("key '" + typePath + "' = " + typeValue.dump() + " is not a known type; valid types are " + quotedList(names) +
           (suggestion ? " (did you mean '" + *suggestion + "'?)" : ""));
    }
    json out = object(*alt->schema, v, path, kVariantTypeKey);
    out[kVariantTypeKey] = alt->typeName;
    return out;
  }

  std::string_view source_;
};

}  // namespace

json resolve(const Schema& schema, const json& input, std::string_view sourceName) {
  return Resolver(sourceName).node(schema, input, "");
}

}  // namespace msim::scene
