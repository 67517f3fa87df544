#pragma once
// A raw serial port (POSIX termios) and a pseudo-terminal pair to emulate one.
//
// SerialPort talks to a USB serial adapter (ROBOTIS U2D2, FTDI: /dev/ttyUSB0) or to the
// slave side of a PseudoTerminal: raw mode, 8 data bits, no parity, 1 stop bit, no flow
// control. It asks FTDI-style adapters for low latency (ASYNC_LOW_LATENCY) where the driver
// allows it, and takes a real port exclusively (TIOCEXCL; not a pseudo-terminal's slave), so
// a second program opening the same port fails with "busy" instead of garbling the bus.
//
// Not thread-safe: one owner reads and writes a port.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace saccade::hw {

/// An open serial port. Movable, not copyable; closes in the destructor.
class SerialPort {
 public:
  /// Opens `path` at `baud` bit/s. Supported rates: 9600, 19200, 38400, 57600, 115200,
  /// 230400, 460800, 500000, 576000, 921600, 1000000, 1152000, 1500000, 2000000, 2500000,
  /// 3000000, 3500000, 4000000. Throws HardwareError naming the path for an unsupported
  /// rate, a missing device, a permission problem (with the usual fix), a busy port, or a
  /// device that is not a terminal. Input already waiting is discarded.
  SerialPort(const std::string& path, int baud);
  ~SerialPort();
  SerialPort(SerialPort&& other) noexcept;
  SerialPort& operator=(SerialPort&& other) noexcept;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// Writes all `size` bytes (waiting while the output buffer is full, up to 1 s). Throws
  /// HardwareError naming the path when the device fails or stays full.
  void Write(const uint8_t* data, size_t size);
  void Write(const std::vector<uint8_t>& data) { Write(data.data(), data.size()); }

  /// Waits up to `timeout` for input, then reads what is there (at most `max` bytes).
  /// Returns the number of bytes read: 0 when nothing arrived within the timeout. Throws
  /// HardwareError naming the path when the device fails or hangs up (unplugged adapter,
  /// closed pseudo-terminal).
  size_t Read(uint8_t* buffer, size_t max, std::chrono::microseconds timeout);

  /// Discards every byte received but not yet read.
  void DrainInput();

  const std::string& path() const { return path_; }
  int baud() const { return baud_; }
  /// The file descriptor (-1 after a move).
  int fd() const { return fd_; }

  /// Whether `baud` is one of the supported rates.
  static bool IsSupportedBaud(int baud);
  /// The supported rates, ascending.
  static const std::vector<int>& SupportedBauds();

 private:
  void Close() noexcept;

  std::string path_;
  int baud_ = 0;
  int fd_ = -1;
};

/// A pseudo-terminal pair (posix_openpt): the slave behaves like a serial port for a
/// SerialPort, the master is the other end of the "cable" (the emulated servos).
///
/// Both sides are in raw mode. The object keeps the slave open itself, so that the raw
/// settings persist and the master never sees a hang-up while programs open and close the
/// slave. The master is non-blocking. Movable, not copyable.
class PseudoTerminal {
 public:
  /// Creates the pair. When `symlink` is not empty, also creates a symbolic link at that
  /// path pointing to the slave (replacing a stale link there, never another kind of file);
  /// the destructor removes it. Throws HardwareError naming the path on failure.
  explicit PseudoTerminal(const std::string& symlink = "");
  ~PseudoTerminal();
  PseudoTerminal(PseudoTerminal&& other) noexcept;
  PseudoTerminal& operator=(PseudoTerminal&& other) noexcept;
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  /// The master side's file descriptor (non-blocking, raw). Owned by this object.
  int master_fd() const { return master_fd_; }
  /// The slave's device path, e.g. "/dev/pts/3".
  const std::string& slave_path() const { return slave_path_; }
  /// The symbolic link's path, or "" when none was asked for.
  const std::string& link_path() const { return link_path_; }

 private:
  void Close() noexcept;

  int master_fd_ = -1;
  int slave_fd_ = -1;
  std::string slave_path_;
  std::string link_path_;
};

}  // namespace saccade::hw
