#pragma once
// Running the msim program from a test: a scratch folder per test, the program's exit code and
// output, and scene text written to disk.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;

// inline: each test file uses only some of these.
struct Result {
  int exitCode = -1;
  std::string output;  // stdout and stderr
};

// A JSON file a run wrote (run.json).
inline nlohmann::json readJson(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

inline fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(MSIM_TEST_TMP) / "app" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

inline Result runMsim(const std::string& args) {
  // One log per test (suite and name: two suites may share a test name): ctest runs the tests of
  // this program in parallel processes.
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string test = std::string(info->test_suite_name()) + "." + info->name();
  const fs::path log = fs::path(MSIM_TEST_TMP) / "app" / (test + ".log");
  fs::create_directories(log.parent_path());
  const std::string cmd = std::string(MSIM_APP_PATH) + " " + args + " > " + log.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  Result r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(log);
  std::stringstream ss;
  ss << in.rdbuf();
  r.output = ss.str();
  return r;
}

inline void writeText(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

inline bool noFramesIn(const fs::path& out) {
  if (!fs::exists(out)) return true;
  for (const auto& e : fs::recursive_directory_iterator(out))
    if (e.is_regular_file()) return false;
  return true;
}


// `text` with the first occurrence of `from` replaced by `to` (a test failure if absent).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Runs `scene` and expects exit code 2 (bad input), every needle in the output, and no files.
inline void expectInputError(const std::string& name, const std::string& scene, const std::vector<std::string>& needles) {
  const fs::path dir = scratch(name);
  writeText(dir / "s.json", scene);
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 2) << r.output;
  for (const auto& n : needles) EXPECT_NE(r.output.find(n), std::string::npos) << n << "\n" << r.output;
  EXPECT_TRUE(noFramesIn(dir / "out"));
}
