#pragma once
// The message of the InputError `action` throws, or "" if it throws none (tests of bad input).
#include <string>

#include "msim/core/error.hpp"

template <typename Action>
std::string inputErrorMessage(Action&& action) {
  try {
    action();
  } catch (const msim::InputError& e) {
    return e.what();
  }
  return {};
}
