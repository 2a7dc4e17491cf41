#include "msim/scene/schema/json_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "msim/core/error.hpp"

namespace msim::scene {
namespace {

std::filesystem::path writeTemp(const std::string& name, const std::string& text) {
  const std::filesystem::path dir = std::filesystem::path(MSIM_TEST_TMP) / "scene_schema";
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string loadError(const std::filesystem::path& path) {
  try {
    loadJsonFile(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(LoadJsonFile, ParsesValidFileWithComments) {
  const auto path = writeTemp("valid.json", "{\n  // cell count\n  \"resolution\": 64 /* per axis */\n}\n");
  EXPECT_EQ(loadJsonFile(path)["resolution"], 64);
}

TEST(LoadJsonFile, NumberBeyondDoubleReportsLineAndColumn) {
  // nlohmann refuses it with out_of_range, not parse_error: once it escaped as exit code 1.
  const auto path = writeTemp("huge.json", "{\n  \"time\": {\"duration\": 1e400}\n}\n");
  EXPECT_EQ(loadError(path), path.string() + ":2:24: the number '1e400' is beyond the range of double");
}

TEST(LoadJsonFile, MissingFileIsNamed) {
  const auto path = std::filesystem::path(MSIM_TEST_TMP) / "no_such_scene.json";
  EXPECT_EQ(loadError(path), "scene file '" + path.string() + "' not found");
}

TEST(LoadJsonFile, TrailingCommaReportsLineAndColumnOfClosingBrace) {
  // The '}' on line 4, column 1 is where a key was expected.
  const auto path = writeTemp("trailing_comma.json", "{\n  \"a\": 1,\n  \"b\": 2,\n}\n");
  const std::string msg = loadError(path);
  EXPECT_EQ(msg.rfind(path.string() + ":4:1: malformed JSON: ", 0), 0u) << msg;
  EXPECT_NE(msg.find("unexpected '}'"), std::string::npos) << msg;
}

TEST(LoadJsonFile, MissingCommaReportsPositionOfNextKey) {
  // Line 3 is `    "b": 2` with the opening quote of "b" in column 5.
  const auto path = writeTemp("missing_comma.json", "{\n  \"a\": 1\n    \"b\": 2\n}\n");
  const std::string msg = loadError(path);
  EXPECT_EQ(msg.rfind(path.string() + ":3:5: malformed JSON: ", 0), 0u) << msg;
}

TEST(LoadJsonFile, ErrorOnFirstLineCountsColumnsFromOne) {
  const auto path = writeTemp("first_line.json", "[1, 2, ]");
  EXPECT_EQ(loadError(path).rfind(path.string() + ":1:8: malformed JSON: ", 0), 0u) << loadError(path);
}

TEST(LoadJsonFile, TruncatedFileReportsEndOfInput) {
  const auto path = writeTemp("truncated.json", "{\n  \"a\": [1, 2");
  const std::string msg = loadError(path);
  EXPECT_EQ(msg.rfind(path.string() + ":2:13: malformed JSON: ", 0), 0u) << msg;
}

}  // namespace
}  // namespace msim::scene
