#include "msim/core/log.hpp"

#include <memory>
#include <mutex>
#include <string>

#include <spdlog/sinks/stdout_color_sinks.h>

#include "msim/core/error.hpp"

namespace msim {

namespace {

struct LoggingState {
  std::mutex mutex;
  std::shared_ptr<spdlog::logger> logger;
  spdlog::level::level_enum level = spdlog::level::info;
  bool quiet = false;
};

LoggingState& state() {
  static LoggingState s;
  return s;
}

// Caller holds the state mutex.
spdlog::logger& ensureLogger(LoggingState& s) {
  if (!s.logger) {
    s.logger = spdlog::get("msim");
    if (!s.logger) s.logger = spdlog::stderr_color_mt("msim");
    s.logger->set_pattern("[%H:%M:%S.%e] [%^%L%$] %v");
    // Warnings and errors reach the terminal at once even if the run is killed afterwards.
    s.logger->flush_on(spdlog::level::warn);
    s.logger->set_level(s.quiet ? spdlog::level::err : s.level);
    spdlog::set_default_logger(s.logger);
  }
  return *s.logger;
}

}  // namespace

void initLogging(spdlog::level::level_enum level) {
  LoggingState& s = state();
  std::lock_guard lock(s.mutex);
  s.level = level;
  ensureLogger(s).set_level(s.quiet ? spdlog::level::err : level);
}

void setQuiet(bool quiet) {
  LoggingState& s = state();
  std::lock_guard lock(s.mutex);
  s.quiet = quiet;
  ensureLogger(s).set_level(quiet ? spdlog::level::err : s.level);
}

spdlog::logger& logger() {
  LoggingState& s = state();
  std::lock_guard lock(s.mutex);
  return ensureLogger(s);
}

spdlog::level::level_enum parseLogLevel(std::string_view name) {
  using spdlog::level::level_enum;
  struct Named {
    std::string_view name;
    level_enum level;
  };
  static constexpr Named kLevels[] = {{"trace", level_enum::trace}, {"debug", level_enum::debug},
                                      {"info", level_enum::info},   {"warn", level_enum::warn},
                                      {"error", level_enum::err},   {"off", level_enum::off}};
  for (const auto& l : kLevels)
    if (l.name == name) return l.level;
  throw InputError("unknown log level '" + std::string(name) + "' (expected trace, debug, info, warn, error or off)");
}

}  // namespace msim
