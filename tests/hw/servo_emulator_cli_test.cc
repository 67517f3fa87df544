// The saccade-servo-emulator program, run as a child process and driven with DynamixelBus.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "saccade/hw/dynamixel_bus.h"

extern char** environ;

namespace saccade::hw {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;
namespace tbl = dxl::table;

const char* const kEmulator = SACCADE_SERVO_EMULATOR;
constexpr int kBaud = 1000000;

// A fresh directory under /tmp, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "saccade-emulator-XXXXXX").string();
    path_ = mkdtemp(pattern.data());
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// The emulator as a child process with its stdout and stderr on pipes.
class Child {
 public:
  explicit Child(const std::vector<std::string>& args) {
    int out[2];
    int err[2];
    if (pipe(out) != 0 || pipe(err) != 0) throw std::runtime_error("pipe failed");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], 1);
    posix_spawn_file_actions_adddup2(&actions, err[1], 2);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    posix_spawn_file_actions_addclose(&actions, err[0]);
    std::vector<std::string> argv_strings = {kEmulator};
    argv_strings.insert(argv_strings.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& s : argv_strings) argv.push_back(s.data());
    argv.push_back(nullptr);
    const int spawned = posix_spawn(&pid_, kEmulator, &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(out[1]);
    close(err[1]);
    out_ = out[0];
    err_ = err[0];
    if (spawned != 0) throw std::runtime_error(std::string("cannot run ") + kEmulator);
  }
  ~Child() {
    if (pid_ > 0 && !status_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    close(out_);
    close(err_);
  }

  // The next line of stdout (without '\n'), or nullopt after `timeout` or at the end.
  std::optional<std::string> ReadLine(milliseconds timeout = milliseconds(5000)) {
    const Clock::time_point deadline = Clock::now() + timeout;
    while (true) {
      const size_t newline = out_buffer_.find('\n');
      if (newline != std::string::npos) {
        std::string line = out_buffer_.substr(0, newline);
        out_buffer_.erase(0, newline + 1);
        return line;
      }
      const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) return std::nullopt;
      pollfd pfd{out_, POLLIN, 0};
      if (poll(&pfd, 1, static_cast<int>(left.count())) <= 0) continue;
      char buffer[512];
      const ssize_t n = read(out_, buffer, sizeof(buffer));
      if (n <= 0) return std::nullopt;
      out_buffer_.append(buffer, static_cast<size_t>(n));
    }
  }

  // Waits for the exit (up to `timeout`); returns the exit status, or -1 if still running or
  // killed by a signal.
  int Wait(milliseconds timeout = milliseconds(5000)) {
    const Clock::time_point deadline = Clock::now() + timeout;
    while (!status_) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        status_ = status;
        break;
      }
      if (Clock::now() > deadline) return -1;
      std::this_thread::sleep_for(milliseconds(5));
    }
    return WIFEXITED(*status_) ? WEXITSTATUS(*status_) : -1;
  }

  // Everything written to stderr (call after Wait()).
  std::string Stderr() {
    std::string text;
    char buffer[512];
    ssize_t n;
    while ((n = read(err_, buffer, sizeof(buffer))) > 0)
      text.append(buffer, static_cast<size_t>(n));
    return text;
  }

  void Signal(int signal) { kill(pid_, signal); }

 private:
  pid_t pid_ = -1;
  int out_ = -1;
  int err_ = -1;
  std::string out_buffer_;
  std::optional<int> status_;
};

bool Exists(const std::string& path) {
  return std::filesystem::exists(std::filesystem::symlink_status(path));
}

TEST(ServoEmulatorCliTest, ServesTheBusOnItsLinkAndRemovesTheLinkOnSigterm) {
  TempDir dir;
  const std::string link = dir / "servos";
  Child child({"--ids", "1,2,3,4", "--link", link, "--positions-deg", "0,90,-90,45"});
  const std::optional<std::string> line = child.ReadLine();
  ASSERT_TRUE(line.has_value()) << child.Stderr();
  // "saccade-servo-emulator: serving servos 1,2,3,4 (XM430-W350) on /dev/pts/N (link L)".
  // (Parsed by hand: std::regex trips GCC 12's -Wmaybe-uninitialized under the sanitizers.)
  const std::string prefix = "saccade-servo-emulator: serving servos 1,2,3,4 (XM430-W350) on ";
  ASSERT_EQ(line->rfind(prefix, 0), 0u) << *line;
  const std::string rest = line->substr(prefix.size());
  const size_t space = rest.find(' ');
  ASSERT_NE(space, std::string::npos) << *line;
  const std::string slave = rest.substr(0, space);
  EXPECT_EQ(slave.rfind("/dev/pts/", 0), 0u) << *line;
  EXPECT_EQ(rest.substr(space), " (link " + link + ")") << *line;
  EXPECT_EQ(std::filesystem::read_symlink(link).string(), slave);
  {
    DynamixelBus bus(link, kBaud, {milliseconds(100), 2});
    for (uint8_t id : {1, 2, 3, 4}) EXPECT_EQ(bus.Ping(id), 1020);
    // 90 deg from the middle is tick 2048 + 1024.
    const auto positions = bus.SyncRead(tbl::kPresentPosition.address, 4, {1, 2, 3, 4});
    EXPECT_EQ(dxl::GetLE(positions.at(1).data.data(), 4), 2048u);
    EXPECT_EQ(dxl::GetLE(positions.at(2).data.data(), 4), 3072u);
    EXPECT_EQ(dxl::GetLE(positions.at(3).data.data(), 4), 1024u);
    EXPECT_EQ(dxl::GetLE(positions.at(4).data.data(), 4), 2560u);
    bus.WriteU8(2, tbl::kTorqueEnable.address, 1);
    bus.WriteS32(2, tbl::kGoalPosition.address, 3000);
    EXPECT_EQ(bus.ReadS32(2, tbl::kGoalPosition.address), 3000);
  }
  child.Signal(SIGTERM);
  EXPECT_EQ(child.Wait(), 0) << child.Stderr();
  EXPECT_FALSE(Exists(link));
  const std::optional<std::string> last = child.ReadLine();
  ASSERT_TRUE(last.has_value());
  EXPECT_NE(last->find("stopped (SIGTERM)"), std::string::npos) << *last;
}

TEST(ServoEmulatorCliTest, StopsAfterTheDurationAndOnSigint) {
  TempDir dir;
  const std::string link = dir / "servos";
  {
    Child child({"--duration", "0.2", "--link", link});
    ASSERT_TRUE(child.ReadLine().has_value());
    EXPECT_EQ(child.Wait(), 0);
    EXPECT_FALSE(Exists(link));
  }
  {
    Child child({"--link", link});
    ASSERT_TRUE(child.ReadLine().has_value());
    child.Signal(SIGINT);
    EXPECT_EQ(child.Wait(), 0);
    EXPECT_FALSE(Exists(link));
  }
}

TEST(ServoEmulatorCliTest, TimedFaultsHappenOnSchedule) {
  TempDir dir;
  const std::string link = dir / "servos";
  Child child({"--ids", "1,2", "--link", link, "--silent", "2@0.3", "--overload", "1@0.3",
               "--status-every", "0.1"});
  ASSERT_TRUE(child.ReadLine().has_value());
  DynamixelBus bus(link, kBaud, {milliseconds(20), 1});
  // The faults' delays count from the host's first instruction, not from the emulator's
  // start: a host that takes its time to start up still sees them mid-run.
  std::this_thread::sleep_for(milliseconds(500));
  EXPECT_EQ(bus.Ping(2), 1020);  // the first instruction: 0.3 s to go
  EXPECT_EQ(bus.ReadU8(1, tbl::kHardwareErrorStatus.address), 0);
  std::this_thread::sleep_for(milliseconds(500));
  EXPECT_THROW(bus.Ping(2), BusError);
  EXPECT_EQ(bus.ReadU8(1, tbl::kHardwareErrorStatus.address), dxl::hardware_error::kOverload);
  EXPECT_TRUE(bus.alert(1));
  // The status lines name each servo and its errors.
  bool saw_overload = false;
  while (auto line = child.ReadLine(milliseconds(500))) {
    if (line->find("servo 1:") != std::string::npos &&
        line->find("errors overload") != std::string::npos) {
      saw_overload = true;
      break;
    }
  }
  EXPECT_TRUE(saw_overload);
  child.Signal(SIGTERM);
  EXPECT_EQ(child.Wait(), 0);
}

// Status 1 for bad input, as saccade itself (docs/cli.md, "Exit statuses").
TEST(ServoEmulatorCliTest, BadOptionsExitWithStatus1NamingTheOption) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--drop-rate", "2"}, "--drop-rate"},
      {{"--corrupt-rate", "-0.1"}, "--corrupt-rate"},
      {{"--ids", "1,300"}, "--ids: '300' is not a servo id"},
      {{"--ids", "1,1"}, "--ids: servo 1 appears twice"},
      {{"--ids", "1,x"}, "--ids: 'x' is not a number"},
      {{"--positions-deg", "10,20"}, "--positions-deg: 2 values for 4 servos"},
      {{"--positions-deg", "0,0,0,200"}, "--positions-deg: 200 deg"},
      {{"--silent", "9"}, "--silent: servo 9 is not on the bus"},
      {{"--overload", "1@soon"}, "--overload: 'soon' is not a number"},
      {{"--overheat", "1@-1"}, "--overheat: '1@-1': the delay must be >= 0 s"},
      {{"--duration", "-1"}, "--duration"},
      {{"--no-such-option"}, "--no-such-option"},
  };
  for (const auto& [args, expected] : cases) {
    Child child(args);
    EXPECT_EQ(child.Wait(), 1) << args[0];
    const std::string err = child.Stderr();
    EXPECT_NE(err.find(expected), std::string::npos) << "stderr: " << err;
    EXPECT_NE(err.find("saccade-servo-emulator: error:"), std::string::npos) << err;
  }
}

TEST(ServoEmulatorCliTest, HelpExplainsTheOptions) {
  Child child({"--help"});
  std::string text;
  while (auto line = child.ReadLine(milliseconds(2000))) text += *line + "\n";
  EXPECT_EQ(child.Wait(), 0);
  for (const char* option :
       {"--ids", "--link", "--positions-deg", "--drop-rate", "--corrupt-rate", "--silent",
        "--overload", "--overheat", "--seed", "--duration", "--status-every"}) {
    EXPECT_NE(text.find(option), std::string::npos) << option;
  }
  EXPECT_NE(text.find("XM430-W350"), std::string::npos);
}

TEST(ServoEmulatorCliTest, RefusesToReplaceARegularFileWithItsLink) {
  TempDir dir;
  const std::string path = dir / "notes.txt";
  { std::ofstream(path) << "keep"; }
  Child child({"--link", path});
  EXPECT_EQ(child.Wait(), 1);
  EXPECT_NE(child.Stderr().find(path + ": exists and is not a symbolic link"), std::string::npos);
  EXPECT_TRUE(std::filesystem::is_regular_file(path));
}

}  // namespace
}  // namespace saccade::hw
