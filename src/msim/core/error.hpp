#pragma once
// Errors msim reports to the user. InputError is bad input (scene file, command line, data file):
// the message names the file/line or scene key and what was expected; the program exits with 2.
// SimulationError is a run that went wrong (NaN, CFL blow-up): it names step and field; exit 3.
#include <stdexcept>
#include <string>

namespace msim {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct SimulationError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

inline constexpr int kExitInputError = 2;
inline constexpr int kExitSimulationError = 3;
inline constexpr int kExitInterrupted = 130;

}  // namespace msim
