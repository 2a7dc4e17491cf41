#pragma once
// Test sizes for the sanitizer build (`make sanitize`, the asan preset). Instrumented code runs
// 5-20x slower, so checks that take minutes there run a smaller size of the same check: fewer
// grid refinements, a shorter run, fewer samples. MSIM_SANITIZE is set by tests/CMakeLists.txt.

namespace msim::test {

inline constexpr bool kSanitizerBuild = MSIM_SANITIZE;

// `full` in the Release suite, `shortened` under the sanitizers.
template <typename T>
constexpr T fullOrSanitized(T full, T shortened) {
  return kSanitizerBuild ? shortened : full;
}

}  // namespace msim::test
