#pragma once
// Runs the `saccade` program under test (SACCADE_BINARY) as a shell would, or a program in
// the background whose standard output the test reads line by line.

#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

extern char** environ;

namespace saccade::e2e {

struct CommandRun {
  int status = -1;     ///< exit status; -1 when it did not exit normally
  std::string output;  ///< stdout and stderr together
};

/// A shell command line `COMMAND 2>&1`, waiting for it to end.
inline CommandRun Run(const std::string& command_line) {
  const std::string command = command_line + " 2>&1";
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

/// `saccade ARGS 2>&1`, waiting for it to end.
inline CommandRun Saccade(const std::string& args) {
  return Run(std::string(SACCADE_BINARY) + " " + args);
}

/// `argv` (argv[0] the program's path) in the background, its standard output piped to the
/// test; stopped with SIGTERM at the latest when destroyed.
class BackgroundProcess {
 public:
  explicit BackgroundProcess(std::vector<std::string> argv) {
    int out[2];
    if (pipe(out) != 0) return;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    std::vector<char*> args;
    for (std::string& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    if (posix_spawn(&pid_, args[0], &actions, nullptr, args.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    close(out[1]);
    out_ = out[0];
  }
  ~BackgroundProcess() {
    Stop();
    if (out_ >= 0) close(out_);
  }
  BackgroundProcess(const BackgroundProcess&) = delete;
  BackgroundProcess& operator=(const BackgroundProcess&) = delete;

  bool started() const { return pid_ > 0 && out_ >= 0; }
  /// The next line it prints (with its newline); nullopt once its output ends, or when no
  /// whole line came within `timeout` (what came of it is kept for the next call).
  std::optional<std::string> ReadLine(
      std::chrono::milliseconds timeout = std::chrono::milliseconds::max()) {
    using Clock = std::chrono::steady_clock;
    const bool forever = timeout == std::chrono::milliseconds::max();
    const Clock::time_point deadline = forever ? Clock::time_point::max() : Clock::now() + timeout;
    while (true) {
      const std::size_t newline = buffer_.find('\n');
      if (newline != std::string::npos) {
        std::string line = buffer_.substr(0, newline + 1);
        buffer_.erase(0, newline + 1);
        return line;
      }
      if (out_ < 0 || ended_) {
        if (buffer_.empty()) return std::nullopt;
        return std::exchange(buffer_, std::string());  // the last line, without a newline
      }
      int wait_ms = -1;
      if (!forever) {
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        if (left.count() <= 0) return std::nullopt;
        wait_ms = static_cast<int>(std::min<int64_t>(left.count(), 60'000));
      }
      pollfd pfd{out_, POLLIN, 0};
      if (poll(&pfd, 1, wait_ms) <= 0) continue;  // (EINTR or no data yet)
      char chunk[4096];
      const ssize_t n = read(out_, chunk, sizeof chunk);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        ended_ = true;
        continue;
      }
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }
  /// Reads until a line holding `text`, appending every line read to `*seen`; false when the
  /// output ended or `timeout` passed first.
  bool ReadUntil(const std::string& text, std::string* seen, std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (true) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return false;
      const std::optional<std::string> line = ReadLine(left);
      if (!line) return false;
      *seen += *line;
      if (line->find(text) != std::string::npos) return true;
    }
  }
  /// The process id (-1 when it could not start or was stopped).
  pid_t pid() const { return pid_; }
  /// SIGTERM, then everything it prints until it exits; its exit status (-1 when it did not
  /// exit normally or was already stopped).
  int Stop(std::string* rest = nullptr) {
    if (pid_ <= 0) return -1;
    kill(pid_, SIGTERM);
    while (const std::optional<std::string> line = ReadLine()) {
      if (rest != nullptr) *rest += *line;
    }
    int raw = 0;
    waitpid(pid_, &raw, 0);
    pid_ = -1;
    return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  }

 private:
  pid_t pid_ = -1;
  int out_ = -1;
  bool ended_ = false;
  std::string buffer_;  // read but not yet returned
};

}  // namespace saccade::e2e
