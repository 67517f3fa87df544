#include "saccade/core/log.h"

#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

#include <array>
#include <atomic>
#include <cstdlib>
#include <memory>

#include "saccade/core/error.h"

namespace saccade::log {
namespace {

constexpr std::array<const char*, 6> kNames = {"trace", "debug", "info", "warn", "error", "off"};

spdlog::level::level_enum ToSpdlog(Level level) {
  switch (level) {
    case Level::kTrace:
      return spdlog::level::trace;
    case Level::kDebug:
      return spdlog::level::debug;
    case Level::kInfo:
      return spdlog::level::info;
    case Level::kWarn:
      return spdlog::level::warn;
    case Level::kError:
      return spdlog::level::err;
    case Level::kOff:
      break;
  }
  return spdlog::level::off;
}

Level InitialLevel() {
  const char* env = std::getenv("SACCADE_LOG_LEVEL");
  if (env == nullptr || *env == '\0') return Level::kInfo;
  try {
    return ParseLevel(env);
  } catch (const InvalidArgument&) {
    return Level::kInfo;  // a bad variable must not stop a program; --log-level says why
  }
}

std::atomic<Level>& CurrentLevel() {
  static std::atomic<Level> level{InitialLevel()};
  return level;
}

// Our own logger (not spdlog's default one, which a host program may configure): stderr,
// unbuffered, one lock per line.
spdlog::logger& Logger() {
  static const std::shared_ptr<spdlog::logger> logger = [] {
    auto sink = std::make_shared<spdlog::sinks::stderr_sink_mt>();
    auto made = std::make_shared<spdlog::logger>("saccade", std::move(sink));
    made->set_pattern("[%l] %v");
    made->set_level(spdlog::level::trace);  // filtered in Enabled()
    made->flush_on(spdlog::level::trace);
    return made;
  }();
  return *logger;
}

}  // namespace

const char* LevelName(Level level) { return kNames[static_cast<std::size_t>(level)]; }

Level ParseLevel(std::string_view name) {
  if (name == "warning") return Level::kWarn;
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    if (name == kNames[i]) return static_cast<Level>(i);
  }
  throw InvalidArgument(fmt::format(
      "log level: '{}' is not a level (expected trace, debug, info, warn, error or off)", name));
}

void SetLevel(Level level) { CurrentLevel().store(level); }
Level GetLevel() { return CurrentLevel().load(); }

void Write(Level level, std::string_view message) {
  if (!Enabled(level)) return;
  Logger().log(ToSpdlog(level), "{}", message);
}

}  // namespace saccade::log
