#include "msim/scene/schema/describe.hpp"

#include <algorithm>
#include <array>

#include "msim/scene/schema/key_suggestion.hpp"
#include "msim/scene/schema/schema_text.hpp"

namespace msim::scene {
namespace {

std::string defaultText(const Schema& s) {
  if (s.isRequired()) return "required";
  return s.defaultJson() ? valueText(*s.defaultJson()) : "";
}

std::string variantTypeDescription(const Schema& s) {
  std::vector<std::string> names;
  for (const auto& a : s.alternatives()) names.push_back(a.typeName);
  return (s.description().empty() ? "" : s.description() + "; ") + "type: one of " + quotedList(names);
}

void describeNode(const Schema& s, const json& v, const std::string& path, std::vector<ParamRow>& rows) {
  switch (s.type()) {
    case SchemaType::Object:
      for (const auto& f : s.fields())
        if (v.contains(f.name)) describeNode(*f.schema, v[f.name], childPath(path, f.name), rows);
      return;
    case SchemaType::Array:
      if (v.empty()) rows.push_back({path, "[]", defaultText(s), "", s.description()});
      for (std::size_t i = 0; i < v.size(); ++i) describeNode(s.itemSchema(), v[i], indexPath(path, i), rows);
      return;
    case SchemaType::Variant: {
      const std::string typeName = v.at(kVariantTypeKey).get<std::string>();
      rows.push_back({childPath(path, kVariantTypeKey), typeName, defaultText(s), "", variantTypeDescription(s)});
      if (const auto* alt = s.findAlternative(typeName)) describeNode(*alt->schema, v, path, rows);
      return;
    }
    default: rows.push_back({path, valueText(v), defaultText(s), s.unit(), s.description()});
  }
}

std::string escapeMarkdownCell(std::string text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

void referenceRows(const Schema& s, const std::string& path, const std::string& context, std::string& out) {
  const auto row = [&](const std::string& key, const std::string& type, const std::string& def, const std::string& unit,
                       const std::string& description) {
    out += "| `" + key + "` | " + escapeMarkdownCell(type) + " | " + escapeMarkdownCell(def) + " | " + unit + " | " +
           escapeMarkdownCell(context + description) + " |\n";
  };
  switch (s.type()) {
    case SchemaType::Object:
      for (const auto& f : s.fields()) referenceRows(*f.schema, childPath(path, f.name), context, out);
      return;
    case SchemaType::Array: {
      const Schema& item = s.itemSchema();
      const bool structured = item.type() == SchemaType::Object || item.type() == SchemaType::Variant;
      row(path, structured ? "array of objects" : "array of " + typeLabel(item), defaultText(s), item.unit(),
          s.description());
      if (structured) referenceRows(item, path + "[]", context, out);
      return;
    }
    case SchemaType::Variant:
      row(childPath(path, kVariantTypeKey), "string", defaultText(s), "", variantTypeDescription(s));
      for (const auto& a : s.alternatives())
        referenceRows(*a.schema, path, context + "(type `" + a.typeName + "`) ", out);
      return;
    default: row(path, typeLabel(s), defaultText(s), s.unit(), s.description());
  }
}

}  // namespace

std::vector<ParamRow> describe(const Schema& schema, const json& resolved) {
  std::vector<ParamRow> rows;
  describeNode(schema, resolved, "", rows);
  return rows;
}

std::string formatParamTable(const std::vector<ParamRow>& rows) {
  // Columns before the description are capped so one long value (a scene's free-text
  // description, a mesh path) does not push every other row off the screen; a cut value ends in "...".
  constexpr std::size_t kMaxWidth = 36;
  const auto fit = [](const std::string& text) {
    return text.size() <= kMaxWidth ? text : text.substr(0, kMaxWidth - 3) + "...";
  };
  const auto cells = [&](const ParamRow& r) {
    return std::array<std::string, 5>{fit(r.path), fit(r.value), fit(r.defaultValue), fit(r.unit), r.description};
  };
  const std::array<std::string, 5> header{"parameter", "value", "default", "unit", "description"};
  std::array<std::size_t, 5> width{};
  for (std::size_t c = 0; c < 5; ++c) width[c] = header[c].size();
  for (const auto& r : rows) {
    const auto cs = cells(r);
    for (std::size_t c = 0; c < 5; ++c) width[c] = std::max(width[c], cs[c].size());
  }
  const auto line = [&](const std::array<std::string, 5>& cs) {
    std::string text;
    for (std::size_t c = 0; c < 5; ++c) {
      text += cs[c];
      // The last column is not padded: trailing spaces only make copy-paste worse.
      if (c + 1 < 5) text += std::string(width[c] - cs[c].size() + 2, ' ');
    }
    text.erase(text.find_last_not_of(' ') + 1);
    return text + "\n";
  };
  std::string out = line(header);
  for (const auto& r : rows) out += line(cells(r));
  return out;
}

std::string markdownReference(const Schema& schema) {
  std::string out = "| Key | Type | Default | Unit | Description |\n|---|---|---|---|---|\n";
  referenceRows(schema, "", "", out);
  return out;
}

}  // namespace msim::scene
