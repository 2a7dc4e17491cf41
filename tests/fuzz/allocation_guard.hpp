#pragma once
// The fuzz tests' watch on memory: this test program replaces the global operator new, so every
// allocation made while reading a mutated file (OpenVDB's and the standard library's included)
// passes through it. A single request above kHugeAllocation is refused with std::bad_alloc and
// counted: a reader that sizes a buffer from a damaged count must be caught here even when it
// would turn the bad_alloc into a tidy error message.
#include <cstddef>

namespace msim::fuzz {

inline constexpr std::size_t kHugeAllocation = std::size_t(1) << 30;  // 1 GiB, far above any case's needs

// Requests refused so far, and the largest one.
std::size_t hugeAllocationCount();
std::size_t largestHugeAllocation();

}  // namespace msim::fuzz
