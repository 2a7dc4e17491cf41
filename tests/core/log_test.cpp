// Logging setup: level names and quiet mode.
#include <gtest/gtest.h>

#include "msim/core/error.hpp"
#include "msim/core/log.hpp"

using namespace msim;

TEST(Log, ParsesLevelNames) {
  EXPECT_EQ(parseLogLevel("debug"), spdlog::level::debug);
  EXPECT_EQ(parseLogLevel("error"), spdlog::level::err);
  EXPECT_EQ(parseLogLevel("off"), spdlog::level::off);
  EXPECT_THROW(parseLogLevel("loud"), InputError);
}

TEST(Log, QuietModeKeepsOnlyErrorsAndRestoresTheLevel) {
  initLogging(spdlog::level::debug);
  EXPECT_EQ(logger().level(), spdlog::level::debug);
  EXPECT_EQ(spdlog::default_logger_raw(), &logger());
  setQuiet(true);
  EXPECT_FALSE(logger().should_log(spdlog::level::warn));
  EXPECT_TRUE(logger().should_log(spdlog::level::err));
  initLogging(spdlog::level::trace);  // still quiet
  EXPECT_EQ(logger().level(), spdlog::level::err);
  setQuiet(false);
  EXPECT_EQ(logger().level(), spdlog::level::trace);
  initLogging(spdlog::level::info);
}
