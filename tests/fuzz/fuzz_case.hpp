#pragma once
// One fuzz case: a reader run on one mutated input must return, or throw InputError with a
// message (what msim reports with exit code 2). Anything else fails the test naming the case:
// another exception, a request for a huge allocation (allocation_guard.hpp), or a case slower
// than kCaseTimeLimit (a reader that loops on a damaged count). A failing input is kept under
// MSIM_TEST_TMP/fuzz/failures to reproduce it.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <typeinfo>

#include "allocation_guard.hpp"
#include "msim/core/error.hpp"

namespace msim::fuzz {

// Generous for the sanitizer build; a well-behaved case takes milliseconds.
inline constexpr double kCaseTimeLimit = 10.0;  // seconds

inline std::filesystem::path fuzzScratch(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(MSIM_TEST_TMP) / "fuzz" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void writeBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

inline std::string readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

struct Outcomes {
  int accepted = 0;
  int rejected = 0;
};

// Runs read() on the mutated input at `input` (its bytes are kept if the case fails).
template <typename Read>
void runCase(const std::string& caseName, const std::filesystem::path& input, Read&& read, Outcomes& outcomes) {
  const std::size_t hugeBefore = hugeAllocationCount();
  const auto start = std::chrono::steady_clock::now();
  std::string failure;
  try {
    read();
    ++outcomes.accepted;
  } catch (const InputError& e) {
    if (std::string(e.what()).empty()) failure = "InputError without a message";
    ++outcomes.rejected;
  } catch (const std::exception& e) {
    failure = std::string("threw ") + typeid(e).name() + " instead of InputError: " + e.what();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (hugeAllocationCount() != hugeBefore)
    failure += " asked for a huge allocation (" + std::to_string(largestHugeAllocation()) + " bytes at most)";
  if (seconds > kCaseTimeLimit) failure += " took " + std::to_string(seconds) + " s";
  if (failure.empty()) return;
  const std::filesystem::path kept = std::filesystem::path(MSIM_TEST_TMP) / "fuzz" / "failures" / (caseName + input.extension().string());
  std::filesystem::create_directories(kept.parent_path());
  std::filesystem::copy_file(input, kept, std::filesystem::copy_options::overwrite_existing);
  ADD_FAILURE() << caseName << ":" << failure << " (input kept as " << kept.string() << ")";
}

}  // namespace msim::fuzz
