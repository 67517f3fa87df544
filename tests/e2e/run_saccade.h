#pragma once
// Runs the `saccade` program under test (SACCADE_BINARY) as a shell would.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace saccade::e2e {

struct CommandRun {
  int status = -1;     ///< exit status; -1 when it did not exit normally
  std::string output;  ///< stdout and stderr together
};

/// `saccade ARGS 2>&1`, waiting for it to end.
inline CommandRun Saccade(const std::string& args) {
  const std::string command = std::string(SACCADE_BINARY) + " " + args + " 2>&1";
  CommandRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    run.output.append(buffer.data(), n);
  const int raw = pclose(pipe);
  run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return run;
}

}  // namespace saccade::e2e
