#pragma once
// Wall time elapsed since a steady-clock instant, for solvers' per-stage statistics (timer.hpp
// keeps the run's stage table).
#include <chrono>

namespace msim {

inline double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace msim
