#pragma once
// Logging through spdlog: one logger named "msim" writing to stderr (stdout stays free for data
// and the progress display), with a compact "[12:34:56.789] [I] message" pattern. It is also
// made spdlog's default logger, so spdlog::info(...) anywhere goes through it.
#include <string_view>

#include <spdlog/spdlog.h>

namespace msim {

// Creates (once) and configures the msim logger; later calls only change the level.
void initLogging(spdlog::level::level_enum level = spdlog::level::info);

// Quiet mode: only errors get through until setQuiet(false) restores the initLogging level.
void setQuiet(bool quiet);

// The msim logger; initialised at info level on first use if initLogging was not called.
spdlog::logger& logger();

// "trace", "debug", "info", "warn", "error" or "off"; anything else throws InputError.
spdlog::level::level_enum parseLogLevel(std::string_view name);

}  // namespace msim
