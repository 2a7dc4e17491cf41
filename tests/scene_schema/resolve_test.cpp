#include "msim/scene/schema/resolve.hpp"

#include <gtest/gtest.h>

#include <string>

#include "msim/core/error.hpp"
#include "sample_schema.hpp"

namespace msim::scene {
namespace {

using testing::sampleSchema;

// The InputError message of resolving `input`, or "" when it resolves.
std::string resolveError(const json& input) {
  try {
    resolve(sampleSchema(), input, "scene.json");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

json minimalScene() { return json::parse(R"({"name": "test"})"); }

TEST(Resolve, FillsDefaultsOfNestedObjects) {
  const json out = resolve(sampleSchema(), minimalScene(), "scene.json");
  EXPECT_EQ(out["name"], "test");
  EXPECT_EQ(out["domain"]["resolution"], 64);
  EXPECT_EQ(out["domain"]["boundary"], "open");
  EXPECT_EQ(out["domain"]["max"], json::parse("[1.0, 1.0, 1.0]"));
  EXPECT_DOUBLE_EQ(out["dissipation"].get<double>(), 0.0);
  EXPECT_EQ(out["preview"], true);
  EXPECT_TRUE(out["sources"].is_array());
  EXPECT_TRUE(out["sources"].empty());
}

TEST(Resolve, KeepsGivenValuesAndConvertsNumbers) {
  json in = minimalScene();
  in["domain"] = {{"resolution", 128.0}};
  in["dissipation"] = 2;
  const json out = resolve(sampleSchema(), in, "scene.json");
  EXPECT_TRUE(out["domain"]["resolution"].is_number_integer());
  EXPECT_EQ(out["domain"]["resolution"], 128);
  EXPECT_TRUE(out["dissipation"].is_number_float());
  EXPECT_EQ(out["domain"]["min"], json::parse("[0.0, 0.0, 0.0]"));
}

TEST(Resolve, UnknownKeyNamesFullPathAndSuggestsClosestKey) {
  json in = minimalScene();
  in["sources"] = json::parse(R"([{"shape": {"type": "sphere", "center": [0,0,0], "radius": 1}},
                                  {"shape": {"type": "sphere", "center": [0,0,0], "radius": 1}, "rat": 2}])");
  EXPECT_EQ(resolveError(in), "scene.json: unknown key 'sources[1].rat'; did you mean 'rate'?");
}

TEST(Resolve, UnknownKeyWithoutCloseMatchListsValidKeys) {
  json in = minimalScene();
  in["domain"] = {{"zzzzzzzz", 1}};
  const std::string msg = resolveError(in);
  EXPECT_NE(msg.find("unknown key 'domain.zzzzzzzz'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'resolution'"), std::string::npos) << msg;
}

TEST(Resolve, TransposedLettersAreSuggested) {
  json in = minimalScene();
  in["domain"] = {{"resolutoin", 32}};
  EXPECT_NE(resolveError(in).find("did you mean 'resolution'?"), std::string::npos);
}

TEST(Resolve, WrongTypeNamesKeyExpectationAndValue) {
  json in = minimalScene();
  in["domain"] = {{"resolution", "abc"}};
  EXPECT_EQ(resolveError(in), "scene.json: key 'domain.resolution' expected an integer >= 1, got string \"abc\"");
  in["domain"] = {{"resolution", 2.5}};
  EXPECT_NE(resolveError(in).find("got number 2.5"), std::string::npos);
  in["domain"] = {{"min", {0, 0}}};
  EXPECT_NE(resolveError(in).find("key 'domain.min' expected a vector of 3 numbers"), std::string::npos);
}

TEST(Resolve, OutOfRangeNamesKeyValueAndRange) {
  json in = minimalScene();
  in["dissipation"] = 11;
  EXPECT_EQ(resolveError(in), "scene.json: key 'dissipation' = 11 is out of range: expected a number in [0, 10]");
  in["dissipation"] = 1;
  in["domain"] = {{"resolution", 0}};
  EXPECT_NE(resolveError(in).find("key 'domain.resolution' = 0 is out of range: expected an integer >= 1"),
            std::string::npos);
}

TEST(Resolve, ExclusiveMinimumRejectsTheBoundItself) {
  json in = minimalScene();
  in["sources"] = json::parse(R"([{"shape": {"type": "sphere", "center": [0,0,0], "radius": 0}}])");
  EXPECT_NE(resolveError(in).find("key 'sources[0].shape.radius' = 0 is out of range: expected a number > 0"),
            std::string::npos);
}

TEST(Resolve, MissingRequiredKeyIsNamed) {
  const std::string msg = resolveError(json::object());
  EXPECT_NE(msg.find("scene.json: missing required key 'name'"), std::string::npos) << msg;
  json in = minimalScene();
  in["sources"] = json::parse(R"([{"shape": {"type": "sphere", "center": [0,0,0]}}])");
  EXPECT_NE(resolveError(in).find("missing required key 'sources[0].shape.radius'"), std::string::npos);
}

TEST(Resolve, StringChoicesAreEnforcedWithSuggestion) {
  json in = minimalScene();
  in["domain"] = {{"boundary", "closd"}};
  const std::string msg = resolveError(in);
  EXPECT_NE(msg.find("key 'domain.boundary' expected one of 'open', 'closed'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("did you mean 'closed'?"), std::string::npos) << msg;
}

TEST(Resolve, ArrayLengthLimitsAreChecked) {
  json in = minimalScene();
  const json source = json::parse(R"({"shape": {"type": "sphere", "center": [0,0,0], "radius": 1}})");
  in["sources"] = json::array({source, source, source, source, source});
  EXPECT_NE(resolveError(in).find("key 'sources' has 5 items; expected between 0 and 4"), std::string::npos);
}

TEST(Resolve, VariantDispatchesOnType) {
  json in = minimalScene();
  in["sources"] = json::parse(R"([{"shape": {"type": "box", "min": [0,0,0], "max": [1,2,3]}, "rate": 3},
                                  {"shape": {"type": "capsule", "a": [0,0], "b": [1,0], "radius": 0.5}}])");
  const json out = resolve(sampleSchema(), in, "scene.json");
  EXPECT_EQ(out["sources"][0]["shape"]["type"], "box");
  EXPECT_EQ(out["sources"][0]["shape"]["max"], json::parse("[1.0, 2.0, 3.0]"));
  EXPECT_DOUBLE_EQ(out["sources"][0]["rate"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(out["sources"][1]["rate"].get<double>(), 1.0);
  EXPECT_EQ(out["sources"][1]["shape"]["type"], "capsule");
  EXPECT_EQ(out["sources"][1]["shape"]["b"].size(), 2u);
}

TEST(Resolve, VariantRejectsKeysOfAnotherAlternative) {
  json in = minimalScene();
  in["sources"] = json::parse(R"([{"shape": {"type": "box", "min": [0,0,0], "max": [1,1,1], "radius": 1}}])");
  EXPECT_NE(resolveError(in).find("unknown key 'sources[0].shape.radius'"), std::string::npos);
}

TEST(Resolve, UnknownVariantTypeListsValidTypes) {
  json in = minimalScene();
  in["sources"] = json::parse(R"([{"shape": {"type": "cube", "min": [0,0,0]}}])");
  EXPECT_EQ(resolveError(in),
            "scene.json: key 'sources[0].shape.type' = \"cube\" is not a known type; valid types are 'sphere', 'box', "
            "'capsule', 'plane', 'mesh'");
  in["sources"] = json::parse(R"([{"shape": {"center": [0,0,0]}}])");
  EXPECT_NE(resolveError(in).find("missing required key 'sources[0].shape.type' (one of 'sphere'"), std::string::npos);
}

TEST(Resolve, RootMustBeAnObject) {
  try {
    resolve(sampleSchema(), json::array(), "bad.json");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "bad.json: the scene must be an object, got array []");
  }
}

}  // namespace
}  // namespace msim::scene
