#pragma once
// Shared by the head driver tests: waiting on a driver's status in real time.
#include <chrono>
#include <numbers>
#include <string>
#include <thread>

#include "saccade/hw/head_driver.h"

namespace saccade::hw::testing {

inline constexpr double kDeg = std::numbers::pi / 180.0;
inline const std::string kPopeye = SACCADE_SOURCE_DIR "/robots/popeye.yaml";

inline void Sleep(double seconds) {
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
}

/// Reads until `done(status)` or `timeout` seconds, polling every `period`; the last status.
template <typename Done>
HeadStatus ReadUntil(HeadDriver& driver, Done done, double timeout = 3.0, double period = 0.005) {
  const auto start = std::chrono::steady_clock::now();
  HeadStatus status = driver.Read();
  while (!done(status) &&
         std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() <
             timeout) {
    Sleep(period);
    status = driver.Read();
  }
  return status;
}

}  // namespace saccade::hw::testing
