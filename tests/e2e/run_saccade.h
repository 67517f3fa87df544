#pragma once
// Runs the `saccade` program under test (SACCADE_BINARY) as a shell would, or a program in
// the background whose standard output the test reads line by line.

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

extern char** environ;

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
    out_ = fdopen(out[0], "r");
  }
  ~BackgroundProcess() {
    Stop();
    if (out_ != nullptr) fclose(out_);
  }
  BackgroundProcess(const BackgroundProcess&) = delete;
  BackgroundProcess& operator=(const BackgroundProcess&) = delete;

  bool started() const { return pid_ > 0 && out_ != nullptr; }
  /// The next line it prints (with its newline); nullopt once its output ends.
  std::optional<std::string> ReadLine() {
    char line[4096];
    if (out_ == nullptr || std::fgets(line, sizeof line, out_) == nullptr) return std::nullopt;
    return std::string(line);
  }
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
  FILE* out_ = nullptr;
};

}  // namespace saccade::e2e
