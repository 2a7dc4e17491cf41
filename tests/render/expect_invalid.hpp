#pragma once
// EXPECT that a call throws std::invalid_argument whose message mentions `fragment` (the input
// that was wrong), so error messages stay specific.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

template <typename F>
void expectInvalidArgument(F&& f, const std::string& fragment) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected std::invalid_argument mentioning '" << fragment << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
        << "message '" << e.what() << "' does not mention '" << fragment << "'";
  }
}
