#include "saccade/hw/serial_port.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "saccade/hw/hw_error.h"

namespace saccade::hw {
namespace {

using Bytes = std::vector<uint8_t>;
using std::chrono::milliseconds;

// A fresh directory under /tmp, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::string pattern =
        (std::filesystem::temp_directory_path() / "saccade-serial-XXXXXX").string();
    path_ = mkdtemp(pattern.data());
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

// Reads `count` bytes from the (non-blocking) master, waiting up to a second.
Bytes ReadMaster(int fd, size_t count) {
  Bytes out;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (out.size() < count && std::chrono::steady_clock::now() < deadline) {
    pollfd pfd{fd, POLLIN, 0};
    if (poll(&pfd, 1, 10) <= 0) continue;
    uint8_t buffer[512];
    const ssize_t n = read(fd, buffer, sizeof(buffer));
    if (n > 0) out.insert(out.end(), buffer, buffer + n);
  }
  return out;
}

Bytes ReadPort(SerialPort& port, size_t count) {
  Bytes out;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (out.size() < count && std::chrono::steady_clock::now() < deadline) {
    uint8_t buffer[512];
    const size_t n = port.Read(buffer, sizeof(buffer), milliseconds(10));
    out.insert(out.end(), buffer, buffer + n);
  }
  return out;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const HardwareError& e) {
    return e.what();
  }
  return "(no HardwareError)";
}

TEST(SerialPortTest, EveryByteValueCrossesThePseudoTerminalUnchanged) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path(), 1000000);
  // Raw mode: no CR/LF translation, no XON/XOFF (0x11, 0x13), no signals (0x03), no echo.
  Bytes all(256);
  for (int i = 0; i < 256; ++i) all[static_cast<size_t>(i)] = static_cast<uint8_t>(i);
  port.Write(all);
  EXPECT_EQ(ReadMaster(pty.master_fd(), all.size()), all);
  ASSERT_EQ(write(pty.master_fd(), all.data(), all.size()), 256);
  EXPECT_EQ(ReadPort(port, all.size()), all);
  // Nothing was echoed back to the master.
  EXPECT_TRUE(ReadMaster(pty.master_fd(), 1).empty());
}

TEST(SerialPortTest, ReadReturnsZeroAfterTheTimeout) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path(), 57600);
  uint8_t buffer[8];
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(port.Read(buffer, sizeof(buffer), milliseconds(20)), 0u);
  EXPECT_GE(std::chrono::steady_clock::now() - start, milliseconds(20));
}

TEST(SerialPortTest, DrainInputDiscardsWaitingBytes) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path(), 57600);
  const Bytes stale = {1, 2, 3, 4};
  ASSERT_EQ(write(pty.master_fd(), stale.data(), stale.size()), 4);
  std::this_thread::sleep_for(milliseconds(20));
  port.DrainInput();
  uint8_t buffer[8];
  EXPECT_EQ(port.Read(buffer, sizeof(buffer), milliseconds(20)), 0u);
}

TEST(SerialPortTest, IsMovable) {
  PseudoTerminal pty;
  SerialPort a(pty.slave_path(), 115200);
  SerialPort b = std::move(a);
  EXPECT_EQ(a.fd(), -1);  // NOLINT(bugprone-use-after-move): the moved-from state is specified
  EXPECT_EQ(b.path(), pty.slave_path());
  b.Write(Bytes{0x42});
  EXPECT_EQ(ReadMaster(pty.master_fd(), 1), Bytes{0x42});
}

TEST(SerialPortTest, ReopensAfterClose) {
  PseudoTerminal pty;
  { SerialPort first(pty.slave_path(), 57600); }
  SerialPort second(pty.slave_path(), 57600);
  second.Write(Bytes{7});
  EXPECT_EQ(ReadMaster(pty.master_fd(), 1), Bytes{7});
}

TEST(SerialPortTest, SupportsTheDynamixelBaudRates) {
  for (int baud : {57600, 115200, 1000000, 2000000, 3000000, 4000000}) {
    EXPECT_TRUE(SerialPort::IsSupportedBaud(baud)) << baud;
  }
  PseudoTerminal pty;
  for (int baud : SerialPort::SupportedBauds()) {
    EXPECT_NO_THROW(SerialPort(pty.slave_path(), baud)) << baud;
  }
}

TEST(SerialPortTest, UnsupportedBaudRateNamesThePathAndTheRate) {
  PseudoTerminal pty;
  const std::string message = ErrorOf([&] { SerialPort(pty.slave_path(), 12345); });
  EXPECT_NE(message.find(pty.slave_path() + ": unsupported baud rate 12345"), std::string::npos)
      << message;
  EXPECT_NE(message.find("57600"), std::string::npos) << message;
}

TEST(SerialPortTest, MissingDeviceNamesThePath) {
  const std::string message = ErrorOf([] { SerialPort("/dev/ttyUSB-saccade-missing", 57600); });
  EXPECT_EQ(message.rfind("/dev/ttyUSB-saccade-missing: cannot open the serial port: no such "
                          "device",
                          0),
            0u)
      << message;
}

TEST(SerialPortTest, PermissionProblemSuggestsTheDialoutGroup) {
  if (geteuid() == 0) GTEST_SKIP() << "root opens any file";
  TempDir dir;
  const std::string path = dir / "locked";
  std::ofstream(path) << "x";
  chmod(path.c_str(), 0);
  const std::string message = ErrorOf([&] { SerialPort(path, 57600); });
  EXPECT_NE(message.find(path + ": cannot open the serial port: permission denied"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("dialout"), std::string::npos) << message;
}

TEST(SerialPortTest, AFileThatIsNotATerminalIsRefused) {
  const std::string message = ErrorOf([] { SerialPort("/dev/null", 57600); });
  EXPECT_NE(message.find("/dev/null: is not a serial port"), std::string::npos) << message;
}

TEST(PseudoTerminalTest, CreatesAndRemovesItsSymlink) {
  TempDir dir;
  const std::string link = dir / "servos";
  {
    PseudoTerminal pty(link);
    EXPECT_EQ(pty.link_path(), link);
    EXPECT_EQ(std::filesystem::read_symlink(link).string(), pty.slave_path());
    SerialPort port(link, 57600);  // the link opens as a serial port
    port.Write(Bytes{9});
    EXPECT_EQ(ReadMaster(pty.master_fd(), 1), Bytes{9});
  }
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(link)));
}

TEST(PseudoTerminalTest, ReplacesAStaleSymlink) {
  TempDir dir;
  const std::string link = dir / "servos";
  std::filesystem::create_symlink("/dev/pts/does-not-exist", link);
  PseudoTerminal pty(link);
  EXPECT_EQ(std::filesystem::read_symlink(link).string(), pty.slave_path());
}

TEST(PseudoTerminalTest, NeverReplacesARegularFile) {
  TempDir dir;
  const std::string path = dir / "notes.txt";
  std::ofstream(path) << "keep me";
  const std::string message = ErrorOf([&] { PseudoTerminal pty(path); });
  EXPECT_NE(message.find(path + ": exists and is not a symbolic link"), std::string::npos)
      << message;
  std::ifstream in(path);
  std::string content;
  std::getline(in, content);
  EXPECT_EQ(content, "keep me");
}

TEST(PseudoTerminalTest, LeavesALinkThatWasTakenOverAlone) {
  TempDir dir;
  const std::string link = dir / "servos";
  std::string other_slave;
  {
    PseudoTerminal first(link);
    PseudoTerminal second(link);  // replaces the link: the newest emulator wins the name
    other_slave = second.slave_path();
    first = PseudoTerminal();  // destroying the first must not remove the second's link
    EXPECT_EQ(std::filesystem::read_symlink(link).string(), other_slave);
  }
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(link)));
}

}  // namespace
}  // namespace saccade::hw
