#pragma once
// A fresh, empty scratch directory per test under MSIM_TEST_TMP, named after the running test.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "msim/core/error.hpp"

namespace msim::io::test {

inline std::filesystem::path scratchDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::filesystem::path dir =
      std::filesystem::path(MSIM_TEST_TMP) / "io" / (std::string(info->test_suite_name()) + "." + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void writeText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

inline std::string readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Runs f, expecting an InputError whose message contains every one of `fragments`.
template <typename F>
void expectInputError(F&& f, std::initializer_list<std::string> fragments) {
  try {
    f();
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    for (const auto& fragment : fragments)
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << "'" << e.what() << "' lacks '" << fragment << "'";
  }
}

}  // namespace msim::io::test
