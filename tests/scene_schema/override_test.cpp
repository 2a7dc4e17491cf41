#include "msim/scene/schema/override.hpp"

#include <gtest/gtest.h>

#include <string>

#include "msim/core/error.hpp"

namespace msim::scene {
namespace {

using nlohmann::json;

json scene() {
  return json::parse(R"({"domain": {"resolution": 64, "min": [0, 0, 0]},
                         "sources": [{"rate": 1}, {"rate": 2, "shape": {"type": "sphere", "radius": 0.1}}]})");
}

std::string overrideError(json doc, std::string_view assignment) {
  try {
    applyOverride(doc, assignment);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ApplyOverride, SetsNestedKeyParsingValueAsJson) {
  json doc = scene();
  applyOverride(doc, "domain.resolution=128");
  EXPECT_EQ(doc["domain"]["resolution"], 128);
  applyOverride(doc, "domain.min=[1,2,3]");
  EXPECT_EQ(doc["domain"]["min"], json::parse("[1,2,3]"));
  applyOverride(doc, "preview=false");
  EXPECT_EQ(doc["preview"], false);
}

TEST(ApplyOverride, UnparsableValueBecomesString) {
  json doc = scene();
  applyOverride(doc, "domain.boundary=closed");
  EXPECT_EQ(doc["domain"]["boundary"], "closed");
  applyOverride(doc, "name=");
  EXPECT_EQ(doc["name"], "");
}

TEST(ApplyOverride, ArrayIndexReachesItems) {
  json doc = scene();
  applyOverride(doc, "sources[1].shape.radius=0.25");
  EXPECT_DOUBLE_EQ(doc["sources"][1]["shape"]["radius"].get<double>(), 0.25);
  applyOverride(doc, "domain.min[2]=5");
  EXPECT_EQ(doc["domain"]["min"][2], 5);
  EXPECT_EQ(doc["sources"][0]["rate"], 1);
}

TEST(ApplyOverride, CreatesMissingObjects) {
  json doc = scene();
  applyOverride(doc, "time.fps=30");
  EXPECT_EQ(doc["time"]["fps"], 30);
}

TEST(ApplyOverride, BadPathsAreInputErrors) {
  EXPECT_EQ(overrideError(scene(), "sources[5].rate=1"),
            "--set 'sources[5].rate=1': index 5 is out of range: 'sources' has 2 items");
  EXPECT_NE(overrideError(scene(), "domain.resolution.x=1").find("'domain.resolution' is number 64, not an object"),
            std::string::npos);
  EXPECT_NE(overrideError(scene(), "domain[0]=1").find("not an array"), std::string::npos);
  EXPECT_NE(overrideError(scene(), "outputs[0]=1").find("'outputs' is not set in the scene"), std::string::npos);
  EXPECT_NE(overrideError(scene(), "domain..min=1").find("empty key"), std::string::npos);
  EXPECT_NE(overrideError(scene(), "sources[x].rate=1").find("array index 'x'"), std::string::npos);
  EXPECT_NE(overrideError(scene(), "sources[1.rate=1").find("missing ']'"), std::string::npos);
  EXPECT_NE(overrideError(scene(), "domain.resolution").find("expected key.path=value"), std::string::npos);
  EXPECT_NE(overrideError(scene(), "=3").find("empty key path"), std::string::npos);
}

}  // namespace
}  // namespace msim::scene
