// The GUI server under a local flood (issue 46, item 9): a few hundred idle TCP connections
// need no token, so the server bounds what they can take. HTTP connections are capped
// (max_http_sessions) and time out when idle (http_timeout); when the process runs out of file
// descriptors anyway, a failed accept is retried after a back-off instead of at once (before,
// 150,000 retries in 3 s: a core at 95 %). Plain POSIX sockets to 127.0.0.1, bounded in count
// and time.

#include <arpa/inet.h>
#include <dirent.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "saccade/server/gui_server.h"

namespace saccade::server {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// Waits only for events to happen, never to bound how long they take.
constexpr auto kWait = std::chrono::seconds(10);

// A blocking TCP connection to 127.0.0.1:port; -1 when it cannot be made.
int ConnectTo(uint16_t port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

bool SendAll(int fd, const std::string& bytes) {
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return false;
    sent += static_cast<std::size_t>(n);
  }
  return true;
}

struct Received {
  std::string bytes;
  bool closed = false;  // the server closed the connection (EOF or reset) within the wait
};

// Reads until the server closes the connection or `wait` passes.
Received ReadUntilClosed(int fd, Clock::duration wait = kWait) {
  Received out;
  const auto deadline = Clock::now() + wait;
  char buffer[4096];
  while (Clock::now() < deadline) {
    pollfd p{fd, POLLIN, 0};
    const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
    if (::poll(&p, 1, static_cast<int>(std::max<int64_t>(1, left.count()))) <= 0) continue;
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) {
      out.closed = true;
      return out;
    }
    out.bytes.append(buffer, static_cast<std::size_t>(n));
  }
  return out;
}

// The status of one GET on a new connection (Connection: close); nullopt when the connection
// cannot be made or ends without a status line.
std::optional<int> GetStatus(uint16_t port, const std::string& target = "/api/status") {
  const int fd = ConnectTo(port);
  if (fd < 0) return std::nullopt;
  SendAll(fd, "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
  const Received got = ReadUntilClosed(fd);
  ::close(fd);
  int status = 0;
  if (std::sscanf(got.bytes.c_str(), "HTTP/1.1 %d", &status) != 1) return std::nullopt;
  return status;
}

// Retries GetStatus until it answers (the server sees a closed connection a moment later).
std::optional<int> GetStatusEventually(uint16_t port) {
  const auto deadline = Clock::now() + kWait;
  for (;;) {
    const std::optional<int> status = GetStatus(port);
    if (status || Clock::now() >= deadline) return status;
    std::this_thread::sleep_for(milliseconds(20));
  }
}

ServerOptions LocalOptions() {
  ServerOptions options;
  options.port = 0;
  return options;
}

// ------------------------------------------------------------------------------------------
// The HTTP session cap and the idle timeout
// ------------------------------------------------------------------------------------------

TEST(GuiServerLimitsTest, AConnectionOverMaxHttpSessionsGets503AndIsClosedOthersGoOn) {
  ServerOptions options = LocalOptions();
  options.max_http_sessions = 2;
  GuiServer server(options);
  server.Start();
  // Two idle connections take the two places (accepted in order, before the third).
  const int a = ConnectTo(server.port());
  const int b = ConnectTo(server.port());
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  const int c = ConnectTo(server.port());
  ASSERT_GE(c, 0);
  const Received refused = ReadUntilClosed(c);
  ::close(c);
  EXPECT_TRUE(refused.closed);
  EXPECT_EQ(refused.bytes.rfind("HTTP/1.1 503", 0), 0u) << refused.bytes;
  EXPECT_NE(refused.bytes.find("too many connections"), std::string::npos) << refused.bytes;
  // The two held places still serve requests.
  ASSERT_TRUE(
      SendAll(a, "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n"));
  EXPECT_EQ(ReadUntilClosed(a).bytes.rfind("HTTP/1.1 200", 0), 0u);
  ::close(a);
  // One place is free again: a new client is served.
  EXPECT_EQ(GetStatusEventually(server.port()), 200);
  ::close(b);
}

TEST(GuiServerLimitsTest, WebSocketClientsDoNotCountAgainstMaxHttpSessions) {
  ServerOptions options = LocalOptions();
  options.max_http_sessions = 1;
  GuiServer server(options);
  server.Start();
  std::vector<int> sockets;
  for (int i = 0; i < 3; ++i) {
    const int fd = ConnectTo(server.port());
    ASSERT_GE(fd, 0);
    sockets.push_back(fd);
    ASSERT_TRUE(SendAll(fd,
                        "GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: Upgrade\r\n"
                        "Upgrade: websocket\r\nSec-WebSocket-Version: 13\r\n"
                        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n"));
    // The handshake's answer, read before the next connects: the place is free again.
    std::string answer;
    const auto deadline = Clock::now() + kWait;
    while (answer.find("\r\n\r\n") == std::string::npos && Clock::now() < deadline) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 100) <= 0) continue;
      char buffer[1024];
      const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
      if (n <= 0) break;
      answer.append(buffer, static_cast<std::size_t>(n));
    }
    EXPECT_EQ(answer.rfind("HTTP/1.1 101", 0), 0u) << "client " << i << ": " << answer;
    const auto until = Clock::now() + kWait;
    while (server.client_count() < i + 1 && Clock::now() < until) {
      std::this_thread::sleep_for(milliseconds(5));
    }
  }
  EXPECT_EQ(server.client_count(), 3);
  EXPECT_EQ(GetStatusEventually(server.port()), 200);
  for (const int fd : sockets) ::close(fd);
}

TEST(GuiServerLimitsTest, AnHttpConnectionThatSendsNothingIsClosedAfterTheTimeout) {
  // The default (30 s) is longer than kWait: a server that ignored the option fails here.
  ServerOptions options = LocalOptions();
  options.http_timeout = milliseconds(300);
  GuiServer server(options);
  server.Start();
  const int silent = ConnectTo(server.port());
  const int partial = ConnectTo(server.port());
  const int kept_alive = ConnectTo(server.port());
  ASSERT_GE(silent, 0);
  ASSERT_GE(partial, 0);
  ASSERT_GE(kept_alive, 0);
  // A request that never ends (sent byte by byte, then nothing), and a keep-alive connection
  // that goes idle after its first response.
  ASSERT_TRUE(SendAll(partial, "GET /api/status HTTP/1.1\r\nHost: 127.0"));
  ASSERT_TRUE(SendAll(kept_alive, "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"));
  const Received silent_got = ReadUntilClosed(silent);
  const Received partial_got = ReadUntilClosed(partial);
  const Received kept_alive_got = ReadUntilClosed(kept_alive);
  EXPECT_TRUE(silent_got.closed);
  EXPECT_EQ(silent_got.bytes, "");
  EXPECT_TRUE(partial_got.closed);
  EXPECT_TRUE(kept_alive_got.closed);
  EXPECT_EQ(kept_alive_got.bytes.rfind("HTTP/1.1 200", 0), 0u) << kept_alive_got.bytes;
  for (const int fd : {silent, partial, kept_alive}) ::close(fd);
  EXPECT_EQ(GetStatus(server.port()), 200);
}

TEST(GuiServerLimitsTest, LimitsThatAreNotPositiveThrowNamingThem) {
  ServerOptions sessions = LocalOptions();
  sessions.max_http_sessions = 0;
  ServerOptions timeout = LocalOptions();
  timeout.http_timeout = milliseconds(0);
  for (const ServerOptions& options : {sessions, timeout}) {
    try {
      GuiServer server(options);
      FAIL() << "no exception";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("max_http_sessions and http_timeout must be positive"),
                std::string::npos)
          << e.what();
    }
  }
}

// ------------------------------------------------------------------------------------------
// Out of file descriptors
// ------------------------------------------------------------------------------------------

// The CPU time (user + system) of process `pid` in seconds, from /proc/PID/stat.
double CpuSeconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t paren = stat.rfind(')');
  if (paren == std::string::npos) return -1;
  std::istringstream fields(stat.substr(paren + 2));
  std::vector<std::string> field;
  for (std::string f; fields >> f;) field.push_back(f);
  if (field.size() < 13) return -1;
  // Fields 14 (utime) and 15 (stime) of proc(5); field[0] is field 3 (state).
  const double ticks = std::stod(field[11]) + std::stod(field[12]);
  return ticks / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

// The number of file descriptors process `pid` has open.
int OpenDescriptors(pid_t pid) {
  DIR* dir = ::opendir(("/proc/" + std::to_string(pid) + "/fd").c_str());
  if (dir == nullptr) return -1;
  int count = 0;
  while (const dirent* entry = ::readdir(dir)) {
    if (entry->d_name[0] != '.') ++count;
  }
  ::closedir(dir);
  return count;
}

// What the child running the server tells the test: its port and its file limit.
struct ChildInfo {
  uint16_t port = 0;
  int limit = 0;
};

// Descriptors the server's child may open beyond what it has at the start: the I/O thread's
// epoll, interrupter and timer, the listening socket, and about a dozen connections.
constexpr int kSpareDescriptors = 16;
// Connections of the flood: many times what the child can hold, far below the listen backlog.
constexpr int kFloodConnections = 200;
// How long the child's CPU time is measured while the flood holds it at its file limit.
constexpr auto kMeasured = milliseconds(1500);
// The CPU share the server may take during the flood: its back-off timer wakes it at most
// every 200 ms once it backs off fully; retrying at once took a whole core (95 %).
constexpr double kMaxCpuShare = 0.2;

TEST(GuiServerFloodTest, OutOfFileDescriptorsTheServerBacksOffAndServesOnceTheFloodEnds) {
#if defined(__SANITIZE_ADDRESS__)
  // UBSan's vptr check tests that an object's memory is readable through a pipe of its own;
  // at the file limit it gets none and reports every virtual call as on an invalid object
  // (measured: "member call ... object has invalid vptr, memory cannot be printed" in fmt's
  // buffer, then the child ends). The plain build runs this test.
  GTEST_SKIP() << "out of file descriptors, the sanitizers' own checks fail (ASan+UBSan build)";
#endif
  // The server runs in a child whose file limit is low (the test's own connections need
  // descriptors of their own). The child answers its port and limit, then serves until the
  // pipe from the test closes.
  int to_test[2], to_child[2];
  ASSERT_EQ(::pipe2(to_test, O_CLOEXEC), 0);
  ASSERT_EQ(::pipe2(to_child, O_CLOEXEC), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(to_test[0]);
    ::close(to_child[1]);
    try {
      ChildInfo info;
      info.limit = OpenDescriptors(::getpid()) + kSpareDescriptors;
      rlimit limit{};
      ::getrlimit(RLIMIT_NOFILE, &limit);
      limit.rlim_cur = static_cast<rlim_t>(info.limit);
      if (::setrlimit(RLIMIT_NOFILE, &limit) != 0) ::_exit(3);
      ServerOptions options = LocalOptions();
      options.max_http_sessions = 1000;  // beyond the file limit: the limit is what runs out
      GuiServer server(options);
      server.Start();
      info.port = server.port();
      if (::write(to_test[1], &info, sizeof info) != sizeof info) ::_exit(4);
      char byte = 0;
      while (::read(to_child[0], &byte, 1) > 0) {
      }
      server.Stop();
    } catch (...) {
      ::_exit(2);
    }
    ::_exit(0);
  }
  ::close(to_test[1]);
  ::close(to_child[0]);
  ChildInfo info;
  pollfd p{to_test[0], POLLIN, 0};
  ASSERT_EQ(::poll(&p, 1, static_cast<int>(milliseconds(kWait).count())), 1);
  ASSERT_EQ(::read(to_test[0], &info, sizeof info), static_cast<ssize_t>(sizeof info));
  ::close(to_test[0]);

  std::vector<int> flood;
  for (int i = 0; i < kFloodConnections; ++i) {
    const int fd = ConnectTo(info.port);
    if (fd < 0) break;
    flood.push_back(fd);
  }
  EXPECT_EQ(static_cast<int>(flood.size()), kFloodConnections);
  // The child takes connections until its descriptors run out; the rest wait in the backlog,
  // where every accept fails (EMFILE).
  const auto deadline = Clock::now() + kWait;
  while (OpenDescriptors(child) < info.limit && Clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(10));
  }
  EXPECT_GE(OpenDescriptors(child), info.limit) << "the flood did not reach the file limit";

  const double cpu_before = CpuSeconds(child);
  const auto wall_before = Clock::now();
  std::this_thread::sleep_for(kMeasured);
  const double cpu = CpuSeconds(child) - cpu_before;
  const double wall = std::chrono::duration<double>(Clock::now() - wall_before).count();
  RecordProperty("cpu_share_during_flood", std::to_string(cpu / wall));
  std::printf("server CPU during the flood: %.3f s over %.3f s (%.1f %%)\n", cpu, wall,
              100.0 * cpu / wall);
  EXPECT_LT(cpu / wall, kMaxCpuShare) << "the server spins on accept";

  // The flood ends: a real client is served.
  for (const int fd : flood) ::close(fd);
  EXPECT_EQ(GetStatusEventually(info.port), 200);

  ::close(to_child[1]);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "child status " << status;
}

}  // namespace
}  // namespace saccade::server
