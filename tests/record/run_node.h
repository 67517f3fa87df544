#pragma once
// Runs one of the reference scripts of tests/record/mcap_reference/ (Foxglove's MCAP and ROS 2
// libraries under Node, installed by the setup's `npm ci`) for the record tests.
#include <array>
#include <cstdio>
#include <string>

namespace saccade::record::testing {

/// `node tests/record/mcap_reference/SCRIPT ARGS 2>&1`: its output, and its exit status in
/// `*status`. Each argument is quoted for the shell.
inline std::string RunNode(const std::string& script, const std::string& args, int* status) {
  const std::string line =
      "node " SACCADE_SOURCE_DIR "/tests/record/mcap_reference/" + script + " " + args + " 2>&1";
  std::FILE* pipe = ::popen(line.c_str(), "r");
  if (pipe == nullptr) {
    *status = -1;
    return "(popen failed)";
  }
  std::string out;
  std::array<char, 65536> buffer;
  for (std::size_t n; (n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0;) {
    out.append(buffer.data(), n);
  }
  *status = ::pclose(pipe);
  return out;
}

}  // namespace saccade::record::testing
