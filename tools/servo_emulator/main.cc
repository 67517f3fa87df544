// saccade-servo-emulator: a bus of emulated DYNAMIXEL X-series servos (XM430-W350) on a
// pseudo-terminal, for running the real-robot drivers without the robot, and for tests.
//
// Exit status: 0 after --duration or SIGINT/SIGTERM, 1 when the terminal or link cannot be
// made, 2 for bad options (the message names the option).

#include <fmt/format.h>
#include <signal.h>
#include <time.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/hw/dynamixel_protocol.h"
#include "servo_emulator/servo_emulator.h"

namespace {

namespace dxl = saccade::hw::dxl;
using saccade::hw::ServoEmulator;
using saccade::hw::ServoEmulatorOptions;

constexpr const char* kProgram = "saccade-servo-emulator";

// A bad option: the message names it; exit status 2.
struct OptionError {
  std::string message;
};

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> parts;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    parts.push_back(text.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return parts;
}

double ParseNumber(const std::string& option, const std::string& text) {
  size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value)) {
    throw OptionError{fmt::format("{}: '{}' is not a number", option, text)};
  }
  return value;
}

uint8_t ParseId(const std::string& option, const std::string& text) {
  const double value = ParseNumber(option, text);
  if (value != std::floor(value) || value < 0 || value > dxl::kMaxId) {
    throw OptionError{
        fmt::format("{}: '{}' is not a servo id (expected 0..{})", option, text, dxl::kMaxId)};
  }
  return static_cast<uint8_t>(value);
}

// "ID" or "ID@SECONDS".
struct TimedFault {
  uint8_t id = 0;
  double at = 0.0;  // seconds after the host's first instruction
};

TimedFault ParseTimedFault(const std::string& option, const std::string& text,
                           const std::set<uint8_t>& ids) {
  const size_t at = text.find('@');
  TimedFault fault;
  fault.id = ParseId(option, text.substr(0, at));
  if (!ids.count(fault.id)) {
    throw OptionError{fmt::format("{}: servo {} is not on the bus (see --ids)", option, fault.id)};
  }
  if (at != std::string::npos) {
    fault.at = ParseNumber(option, text.substr(at + 1));
    if (fault.at < 0) {
      throw OptionError{fmt::format("{}: '{}': the delay must be >= 0 s", option, text)};
    }
  }
  return fault;
}

std::string DescribeServo(const saccade::hw::ServoSnapshot& s) {
  const double degrees = (s.position - 2048) * 360.0 / dxl::kTicksPerRevolution;
  return fmt::format(
      "servo {}: position {} ({:+.1f} deg) goal {} velocity {} torque {}{} errors {} "
      "temperature {} C{}",
      s.id, s.position, degrees, s.goal, s.velocity, s.torque ? "on" : "off",
      s.moving ? " moving" : "", dxl::HardwareErrorNames(s.hardware_error), s.temperature,
      s.silent ? " (silent)" : "");
}

int Run(int argc, char** argv) {
  CLI::App app{
      "Emulates a bus of DYNAMIXEL X-series servos (XM430-W350, model 1020) speaking Protocol "
      "2.0 on a pseudo-terminal.\n"
      "Open the printed /dev/pts/N (or the --link) as the serial port, at any baud rate.\n"
      "Each servo has the XM430-W350 control table (Torque Enable 64, Goal Position 116, "
      "Present Position 132, ...), moves to its goal under Profile Velocity/Acceleration, "
      "and follows the e-Manual's rules (EEPROM locked while the torque is on, position "
      "limits, hardware errors cleared only by Reboot).\n"
      "The first line on stdout names the terminal. Stops on SIGINT/SIGTERM or after "
      "--duration, removing the link.\n"
      "Exit status: 0 when stopped, 1 when the terminal or link cannot be made, 2 for bad "
      "options.",
      kProgram};
  std::string ids_text = "1,2,3,4";
  std::string link;
  std::string positions_text;
  double drop_rate = 0.0;
  double corrupt_rate = 0.0;
  std::vector<std::string> silent_specs;
  std::vector<std::string> overload_specs;
  std::vector<std::string> overheat_specs;
  uint64_t seed = 1;
  double duration = 0.0;
  double status_every = 0.0;
  app.add_option("--ids", ids_text, "Servo ids, comma-separated (0..252)")
      ->type_name("ID,...")
      ->capture_default_str();
  app.add_option("--link", link,
                 "Also create a symbolic link to the terminal at PATH (e.g. /tmp/saccade-servos); "
                 "removed on exit")
      ->type_name("PATH");
  app.add_option("--positions-deg", positions_text,
                 "Initial positions in degrees from the middle (tick 2048), one per servo, "
                 "comma-separated, within [-180, 180)")
      ->type_name("DEG,...");
  app.add_option("--drop-rate", drop_rate,
                 "Probability that an instruction packet is ignored, as if lost")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--corrupt-rate", corrupt_rate,
                 "Probability that a status packet gets one byte flipped (its CRC fails)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--silent", silent_specs,
                 "The servo stops answering (as if unplugged), at once or SECONDS after the "
                 "host's first instruction; repeatable")
      ->type_name("ID[@SECONDS]");
  app.add_option("--overload", overload_specs,
                 "The servo raises an overload error (torque off, alert bit) SECONDS after the "
                 "host's first instruction; repeatable")
      ->type_name("ID[@SECONDS]");
  app.add_option("--overheat", overheat_specs,
                 "The servo's temperature rises to 101 C, above its limit "
                 "(overheating error: torque off, alert bit), SECONDS after the host's first "
                 "instruction; repeatable")
      ->type_name("ID[@SECONDS]");
  app.add_option("--seed", seed, "Seed of the random faults")->capture_default_str();
  app.add_option("--duration", duration, "Stop after SECONDS (0: until SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--status-every", status_every,
                 "Print each servo's position, goal, torque and errors every SECONDS (0: never)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: error: %s\nRun with --help for more information.\n", kProgram,
                 e.what());
    return 1;  // bad input: status 1, as saccade (docs/cli.md)
  }

  ServoEmulatorOptions options;
  std::vector<TimedFault> silent;
  std::vector<TimedFault> overload;
  std::vector<TimedFault> overheat;
  try {
    options.ids.clear();
    std::set<uint8_t> ids;
    for (const std::string& part : SplitCommas(ids_text)) {
      const uint8_t id = ParseId("--ids", part);
      if (!ids.insert(id).second) {
        throw OptionError{fmt::format("--ids: servo {} appears twice", id)};
      }
      options.ids.push_back(id);
    }
    if (!positions_text.empty()) {
      const std::vector<std::string> parts = SplitCommas(positions_text);
      if (parts.size() != options.ids.size()) {
        throw OptionError{fmt::format("--positions-deg: {} values for {} servos (--ids {})",
                                      parts.size(), options.ids.size(), ids_text)};
      }
      for (const std::string& part : parts) {
        const double degrees = ParseNumber("--positions-deg", part);
        const long ticks = 2048 + std::lround(degrees * dxl::kTicksPerRevolution / 360.0);
        if (ticks < 0 || ticks > 4095) {
          throw OptionError{fmt::format(
              "--positions-deg: {} deg is outside the encoder's turn [-180, 180)", degrees)};
        }
        options.initial_positions.push_back(static_cast<int32_t>(ticks));
      }
    }
    for (const std::string& s : silent_specs) silent.push_back(ParseTimedFault("--silent", s, ids));
    for (const std::string& s : overload_specs) {
      overload.push_back(ParseTimedFault("--overload", s, ids));
    }
    for (const std::string& s : overheat_specs) {
      overheat.push_back(ParseTimedFault("--overheat", s, ids));
    }
  } catch (const OptionError& e) {
    std::fprintf(stderr, "%s: error: %s\nRun with --help for more information.\n", kProgram,
                 e.message.c_str());
    return 1;  // bad input: status 1, as saccade (docs/cli.md)
  }
  options.drop_rate = drop_rate;
  options.corrupt_rate = corrupt_rate;
  options.seed = seed;

  // SIGINT/SIGTERM are taken synchronously by the main loop (sigtimedwait); blocking them
  // before the emulator's thread starts keeps that thread from receiving them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  ServoEmulator emulator(options);
  std::string slave;
  try {
    slave = emulator.Start(link);
  } catch (const saccade::Error& e) {
    std::fprintf(stderr, "%s: error: %s\n", kProgram, e.what());
    return 1;
  }
  std::string id_list;
  for (uint8_t id : emulator.ids()) id_list += (id_list.empty() ? "" : ",") + std::to_string(id);
  std::printf("%s: serving servos %s (XM430-W350) on %s%s\n", kProgram, id_list.c_str(),
              slave.c_str(), link.empty() ? "" : fmt::format(" (link {})", link).c_str());
  std::fflush(stdout);

  // The timed events, in the order they happen.
  struct Event {
    double at;
    std::function<void()> run;
  };
  std::vector<Event> events;
  for (const TimedFault& f : silent) {
    events.push_back({f.at, [&emulator, f] { emulator.SetSilent(f.id, true); }});
  }
  for (const TimedFault& f : overload) {
    events.push_back({f.at, [&emulator, f] {
                        emulator.InjectHardwareError(f.id, dxl::hardware_error::kOverload);
                      }});
  }
  for (const TimedFault& f : overheat) {
    // Above any Temperature Limit (at most 100 deg C).
    events.push_back({f.at, [&emulator, f] { emulator.SetTemperature(f.id, 101); }});
  }
  std::stable_sort(events.begin(), events.end(),
                   [](const Event& a, const Event& b) { return a.at < b.at; });

  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  size_t next_event = 0;
  double next_status = status_every > 0 ? status_every : -1.0;
  int stop_signal = 0;
  // The faults' clock starts at the host's first instruction (its start-up, however long,
  // does not eat into their delays); the emulator polls for it every kPollS until then. A
  // fault without a delay is there from the start.
  constexpr double kPollS = 0.005;
  std::optional<double> first_instruction;
  while (true) {
    const double now = elapsed();
    if (!first_instruction && emulator.counters().instructions_received > 0) {
      first_instruction = now;
    }
    while (next_event < events.size() &&
           (events[next_event].at <= 0.0 ||
            (first_instruction && events[next_event].at <= now - *first_instruction))) {
      events[next_event++].run();
    }
    if (next_status >= 0 && next_status <= now) {
      for (const auto& s : emulator.Snapshots()) {
        std::printf("t=%.2fs %s\n", now, DescribeServo(s).c_str());
      }
      std::fflush(stdout);
      while (next_status <= now) next_status += status_every;
    }
    if (duration > 0 && now >= duration) break;
    double wake = 3600.0;  // seconds from now
    if (next_event < events.size()) {
      wake = std::min(
          wake, first_instruction ? events[next_event].at - (now - *first_instruction) : kPollS);
    }
    if (next_status >= 0) wake = std::min(wake, next_status - now);
    if (duration > 0) wake = std::min(wake, duration - now);
    wake = std::max(wake, 0.0);
    timespec timeout{};
    timeout.tv_sec = static_cast<time_t>(wake);
    timeout.tv_nsec = static_cast<long>((wake - std::floor(wake)) * 1e9);
    const int sig = sigtimedwait(&signals, nullptr, &timeout);
    if (sig == SIGINT || sig == SIGTERM) {
      stop_signal = sig;
      break;
    }
  }
  emulator.Stop();
  const saccade::hw::EmulatorCounters c = emulator.counters();
  std::printf(
      "%s: stopped%s after %.1f s: %lld instructions, %lld status packets, %lld dropped, "
      "%lld corrupted\n",
      kProgram,
      stop_signal == SIGINT    ? " (SIGINT)"
      : stop_signal == SIGTERM ? " (SIGTERM)"
                               : "",
      elapsed(), static_cast<long long>(c.instructions_received),
      static_cast<long long>(c.status_packets), static_cast<long long>(c.dropped),
      static_cast<long long>(c.corrupted));
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const saccade::Error& e) {
    std::fprintf(stderr, "%s: error: %s\n", kProgram, e.what());
    return 1;
  }
}
