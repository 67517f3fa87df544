#pragma once
// Foxglove's independent ROS 2 serializer under Node (tests/dds/ros2_reference/), for the DDS
// tests: apart from dds_test_util.h so that a test of saccade's own generated types can use it
// without the tests' reference types (both define Cyclone's sequence types).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace saccade::dds::testing {

inline std::string Hex(const std::vector<uint8_t>& bytes) {
  static const char* kDigits = "0123456789abcdef";
  std::string text;
  for (const uint8_t b : bytes) {
    text += kDigits[b >> 4];
    text += kDigits[b & 15];
  }
  return text;
}

/// `n` bytes in base64, as the reference takes a uint8[] field ({"base64": ...}).
inline std::string Base64(const uint8_t* d, std::size_t n) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < n; i += 3) {
    const uint32_t v = (uint32_t{d[i]} << 16) | (i + 1 < n ? uint32_t{d[i + 1]} << 8 : 0) |
                       (i + 2 < n ? uint32_t{d[i + 2]} : 0);
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < n ? k[(v >> 6) & 63] : '=';
    out += i + 2 < n ? k[v & 63] : '=';
  }
  return out;
}
inline std::string Base64(const std::vector<uint8_t>& d) { return Base64(d.data(), d.size()); }

/// Serializes each {"type", "message"} with Foxglove's ROS 2 writer under Node; the hex of
/// each, in order. Fails the test (and returns {}) when Node or its packages are missing.
inline std::vector<std::string> ReferenceSerialize(const nlohmann::json& inputs) {
  const std::filesystem::path dir = SACCADE_SOURCE_DIR "/tests/dds/ros2_reference";
  if (!std::filesystem::exists(dir / "node_modules/@foxglove/rosmsg2-serialization")) {
    ADD_FAILURE() << "the reference serializer's npm packages are missing: run "
                     "scripts/setup.sh (npm ci in tests/dds/ros2_reference)";
    return {};
  }
  const std::filesystem::path input =
      std::filesystem::temp_directory_path() /
      ("saccade-ros2-reference-" + std::to_string(::getpid()) + ".json");
  std::ofstream(input) << inputs.dump();
  const std::string command =
      "node " + (dir / "ros2_serialize.mjs").string() + " " + input.string();
  FILE* pipe = popen(command.c_str(), "r");
  std::vector<std::string> lines;
  std::string line;
  for (int c; (c = std::fgetc(pipe)) != EOF;) {
    if (c == '\n') {
      lines.push_back(line);
      line.clear();
    } else {
      line += static_cast<char>(c);
    }
  }
  const int status = pclose(pipe);
  std::filesystem::remove(input);
  EXPECT_EQ(status, 0) << command;
  return lines;
}

}  // namespace saccade::dds::testing
