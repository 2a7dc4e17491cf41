#include "msim/scene/schema/describe.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "msim/scene/schema/resolve.hpp"
#include "sample_schema.hpp"

namespace msim::scene {
namespace {

using testing::sampleSchema;

const ParamRow* findRow(const std::vector<ParamRow>& rows, const std::string& path) {
  const auto it = std::find_if(rows.begin(), rows.end(), [&](const ParamRow& r) { return r.path == path; });
  return it == rows.end() ? nullptr : &*it;
}
// The result points into rows: a temporary list would leave it dangling.
const ParamRow* findRow(std::vector<ParamRow>&& rows, const std::string& path) = delete;

json resolvedScene() {
  const json in = json::parse(R"({"name": "demo", "domain": {"resolution": 32},
    "sources": [{"shape": {"type": "sphere", "center": [0.5, 0.2, 0.5], "radius": 0.1}, "rate": 2.5}]})");
  return resolve(sampleSchema(), in, "demo.json");
}

TEST(Describe, ListsEveryLeafWithValueDefaultAndUnit) {
  const auto rows = describe(sampleSchema(), resolvedScene());
  const std::vector<std::string> expected{"name",
                                          "domain.min",
                                          "domain.max",
                                          "domain.resolution",
                                          "domain.boundary",
                                          "dissipation",
                                          "preview",
                                          "sources[0].shape.type",
                                          "sources[0].shape.center",
                                          "sources[0].shape.radius",
                                          "sources[0].rate",
                                          "sources[0].temperature"};
  std::vector<std::string> paths;
  for (const auto& r : rows) paths.push_back(r.path);
  EXPECT_EQ(paths, expected);

  const ParamRow* resolution = findRow(rows, "domain.resolution");
  ASSERT_NE(resolution, nullptr);
  EXPECT_EQ(resolution->value, "32");
  EXPECT_EQ(resolution->defaultValue, "64");

  const ParamRow* radius = findRow(rows, "sources[0].shape.radius");
  ASSERT_NE(radius, nullptr);
  EXPECT_EQ(radius->value, "0.1");
  EXPECT_EQ(radius->defaultValue, "required");
  EXPECT_EQ(radius->unit, "m");

  EXPECT_EQ(findRow(rows, "sources[0].rate")->unit, "kg/m^3/s");
  EXPECT_EQ(findRow(rows, "sources[0].temperature")->unit, "K");
  EXPECT_EQ(findRow(rows, "sources[0].temperature")->value, "300");
  EXPECT_EQ(findRow(rows, "domain.min")->value, "[0, 0, 0]");
  EXPECT_EQ(findRow(rows, "dissipation")->unit, "1/s");
  EXPECT_EQ(findRow(rows, "sources[0].shape.type")->value, "sphere");
}

TEST(Describe, EmptyArrayStaysVisible) {
  const json resolved = resolve(sampleSchema(), json::parse(R"({"name": "x"})"), "x.json");
  const auto rows = describe(sampleSchema(), resolved);
  const ParamRow* sources = findRow(rows, "sources");
  ASSERT_NE(sources, nullptr);
  EXPECT_EQ(sources->value, "[]");
}

TEST(FormatParamTable, AlignsColumnsUnderHeader) {
  const std::string table = formatParamTable({{"a", "1", "2", "m", "first"}, {"long.path", "10", "20", "", "second"}});
  EXPECT_EQ(table,
            "parameter  value  default  unit  description\n"
            "a          1      2        m     first\n"
            "long.path  10     20             second\n");
}

TEST(MarkdownReference, DocumentsEveryDeclaredParameter) {
  const std::string md = markdownReference(sampleSchema());
  EXPECT_EQ(md.rfind("| Key | Type | Default | Unit | Description |\n|---|---|---|---|---|\n", 0), 0u);
  EXPECT_NE(md.find("| `domain.resolution` | integer >= 1 | 64 |  | cells along the longest axis |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("| `sources[].rate` | number >= 0 | 1 | kg/m^3/s |"), std::string::npos) << md;
  EXPECT_NE(md.find("| `sources[].shape.radius` | number > 0 | required | m | (type `sphere`) radius |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| `sources[].shape.type` | string | required |"), std::string::npos) << md;
  EXPECT_NE(md.find("| `domain.boundary` | string (open\\|closed) | open |"), std::string::npos) << md;
}

}  // namespace
}  // namespace msim::scene
