#pragma once
// The project's one logger: what library code has to tell a person (a fault, a dropped
// request, a source that ended) goes here, never to stderr by hand. Lines go to stderr as
// "[level] message"; the level is set once per program (`saccade --log-level`, or the
// environment variable SACCADE_LOG_LEVEL) and lines below it cost one comparison.
//
// Backed by spdlog (private to core: no spdlog header here). Thread-safe: any thread may log,
// lines never interleave.
#include <fmt/format.h>

#include <string>
#include <string_view>
#include <utility>

namespace saccade::log {

/// Severity, lowest first. kOff silences everything.
enum class Level { kTrace, kDebug, kInfo, kWarn, kError, kOff };

/// "trace", "debug", "info", "warn", "error", "off".
const char* LevelName(Level level);
/// The level named `name` (as LevelName writes it; "warning" is taken for "warn"). Throws
/// InvalidArgument naming the value got and the names expected.
Level ParseLevel(std::string_view name);

/// Lines below `level` are dropped. The default is kInfo, or SACCADE_LOG_LEVEL when it names
/// a level at the first use of the logger.
void SetLevel(Level level);
Level GetLevel();
/// True when a line at `level` would be written.
inline bool Enabled(Level level) { return level >= GetLevel() && level != Level::kOff; }

/// Writes one line (no trailing newline needed) at `level`.
void Write(Level level, std::string_view message);

/// Formats with fmt and writes, only when `level` is enabled.
template <typename... Args>
void Log(Level level, fmt::format_string<Args...> format, Args&&... args) {
  if (Enabled(level)) Write(level, fmt::format(format, std::forward<Args>(args)...));
}
template <typename... Args>
void Debug(fmt::format_string<Args...> format, Args&&... args) {
  Log(Level::kDebug, format, std::forward<Args>(args)...);
}
template <typename... Args>
void Info(fmt::format_string<Args...> format, Args&&... args) {
  Log(Level::kInfo, format, std::forward<Args>(args)...);
}
template <typename... Args>
void Warn(fmt::format_string<Args...> format, Args&&... args) {
  Log(Level::kWarn, format, std::forward<Args>(args)...);
}
template <typename... Args>
void Error(fmt::format_string<Args...> format, Args&&... args) {
  Log(Level::kError, format, std::forward<Args>(args)...);
}

}  // namespace saccade::log
