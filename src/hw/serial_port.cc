#include "saccade/hw/serial_port.h"

#include <errno.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <linux/serial.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <utility>

#include "saccade/hw/hw_error.h"

namespace saccade::hw {
namespace {

struct BaudRate {
  int baud;
  speed_t code;
};

constexpr BaudRate kBaudRates[] = {{9600, B9600},       {19200, B19200},     {38400, B38400},
                                   {57600, B57600},     {115200, B115200},   {230400, B230400},
                                   {460800, B460800},   {500000, B500000},   {576000, B576000},
                                   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000},
                                   {1500000, B1500000}, {2000000, B2000000}, {2500000, B2500000},
                                   {3000000, B3000000}, {3500000, B3500000}, {4000000, B4000000}};

// The slaves of UNIX98 pseudo-terminals have majors 136..143 (Documentation/admin-guide/devices).
bool IsPseudoTerminalSlave(int fd) {
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISCHR(st.st_mode)) return false;
  const unsigned major_number = major(st.st_rdev);
  return major_number >= 136 && major_number <= 143;
}

std::string Errno(int error) {
  char buffer[256];
  // GNU strerror_r returns the message (possibly not in buffer).
  return strerror_r(error, buffer, sizeof(buffer));
}

// A hint for the errors of a device that went away.
std::string Unplugged(int error) {
  return error == EIO || error == ENXIO || error == ENODEV
             ? " (adapter unplugged, or the emulator stopped?)"
             : "";
}

// Raw 8N1 without flow control; reads return at once (VMIN = VTIME = 0, poll waits).
void MakeRaw(termios* tio) {
  cfmakeraw(tio);
  tio->c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS | CSIZE);
  tio->c_cflag |= CS8 | CLOCAL | CREAD;
  tio->c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  tio->c_cc[VMIN] = 0;
  tio->c_cc[VTIME] = 0;
}

timespec ToTimespec(std::chrono::nanoseconds duration) {
  if (duration.count() < 0) duration = std::chrono::nanoseconds(0);
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(duration.count() / 1000000000);
  ts.tv_nsec = static_cast<long>(duration.count() % 1000000000);
  return ts;
}

}  // namespace

bool SerialPort::IsSupportedBaud(int baud) {
  return std::any_of(std::begin(kBaudRates), std::end(kBaudRates),
                     [baud](const BaudRate& rate) { return rate.baud == baud; });
}

const std::vector<int>& SerialPort::SupportedBauds() {
  static const std::vector<int> bauds = [] {
    std::vector<int> out;
    for (const BaudRate& rate : kBaudRates) out.push_back(rate.baud);
    return out;
  }();
  return bauds;
}

SerialPort::SerialPort(const std::string& path, int baud) : path_(path), baud_(baud) {
  const BaudRate* rate = nullptr;
  for (const BaudRate& r : kBaudRates) {
    if (r.baud == baud) rate = &r;
  }
  if (rate == nullptr) {
    throw HardwareError(path, fmt::format("unsupported baud rate {} bit/s (supported: {})", baud,
                                          fmt::join(SupportedBauds(), ", ")));
  }
  fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    const int error = errno;
    std::string why;
    switch (error) {
      case ENOENT:
        why = "no such device (is the adapter plugged in? see ls /dev/serial/by-id)";
        break;
      case EACCES:
      case EPERM:
        why =
            "permission denied (add the user to the 'dialout' group and log in again, or fix the "
            "udev rule)";
        break;
      case EBUSY:
        why = "the port is busy (another program has it open)";
        break;
      default:
        why = Errno(error);
        break;
    }
    throw HardwareError(path, "cannot open the serial port: " + why);
  }
  try {
    termios tio{};
    if (tcgetattr(fd_, &tio) != 0) {
      throw HardwareError(path, "is not a serial port (tcgetattr: " + Errno(errno) + ")");
    }
    MakeRaw(&tio);
    if (cfsetispeed(&tio, rate->code) != 0 || cfsetospeed(&tio, rate->code) != 0 ||
        tcsetattr(fd_, TCSANOW, &tio) != 0) {
      throw HardwareError(path,
                          fmt::format("cannot set {} bit/s, 8N1, raw: {}", baud, Errno(errno)));
    }
    // FTDI adapters (U2D2) otherwise hold received bytes for 16 ms: far longer than a
    // status packet takes. Best effort: other drivers and pseudo-terminals refuse.
    serial_struct serial{};
    if (ioctl(fd_, TIOCGSERIAL, &serial) == 0) {
      serial.flags |= ASYNC_LOW_LATENCY;
      (void)ioctl(fd_, TIOCSSERIAL, &serial);
    }
    // Exclusive use of a real port. Not on a pseudo-terminal: its emulator keeps the slave
    // open, so the flag would outlive a client that crashed and lock out the next one.
    if (!IsPseudoTerminalSlave(fd_)) (void)ioctl(fd_, TIOCEXCL);
    DrainInput();
  } catch (...) {
    Close();
    throw;
  }
}

SerialPort::~SerialPort() { Close(); }

SerialPort::SerialPort(SerialPort&& other) noexcept
    : path_(std::move(other.path_)), baud_(other.baud_), fd_(std::exchange(other.fd_, -1)) {}

SerialPort& SerialPort::operator=(SerialPort&& other) noexcept {
  if (this != &other) {
    Close();
    path_ = std::move(other.path_);
    baud_ = other.baud_;
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

void SerialPort::Close() noexcept {
  if (fd_ >= 0) {
    (void)ioctl(fd_, TIOCNXCL);
    ::close(fd_);
    fd_ = -1;
  }
}

void SerialPort::Write(const uint8_t* data, size_t size) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd_, data + done, size - done);
    if (n > 0) {
      done += static_cast<size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN) {
      throw HardwareError(path_, "write failed: " + Errno(errno) + Unplugged(errno));
    }
    // The output buffer is full: wait until it drains.
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= std::chrono::nanoseconds(0)) {
      throw HardwareError(
          path_, fmt::format("write timed out after 1 s ({} of {} bytes sent)", done, size));
    }
    pollfd pfd{fd_, POLLOUT, 0};
    const timespec ts = ToTimespec(left);
    if (ppoll(&pfd, 1, &ts, nullptr) < 0 && errno != EINTR) {
      throw HardwareError(path_, "poll failed: " + Errno(errno));
    }
  }
}

size_t SerialPort::Read(uint8_t* buffer, size_t max, std::chrono::microseconds timeout) {
  if (max == 0) return 0;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    const ssize_t n = ::read(fd_, buffer, max);
    if (n > 0) return static_cast<size_t>(n);
    if (n < 0 && errno != EAGAIN && errno != EINTR) {
      throw HardwareError(path_, "read failed: " + Errno(errno) + Unplugged(errno));
    }
    const auto left = deadline - std::chrono::steady_clock::now();
    if (left <= std::chrono::nanoseconds(0)) return 0;
    pollfd pfd{fd_, POLLIN, 0};
    const timespec ts = ToTimespec(left);
    const int ready = ppoll(&pfd, 1, &ts, nullptr);
    if (ready < 0) {
      if (errno == EINTR) continue;
      throw HardwareError(path_, "poll failed: " + Errno(errno));
    }
    if (ready == 0) return 0;
    if ((pfd.revents & (POLLHUP | POLLERR | POLLNVAL)) && !(pfd.revents & POLLIN)) {
      throw HardwareError(path_, "the device hung up (adapter unplugged, or the emulator stopped)");
    }
  }
}

void SerialPort::DrainInput() {
  (void)tcflush(fd_, TCIFLUSH);
  uint8_t scratch[256];
  while (true) {
    const ssize_t n = ::read(fd_, scratch, sizeof(scratch));
    if (n > 0) continue;
    if (n < 0 && errno == EINTR) continue;
    break;  // EAGAIN: empty; anything else shows up at the next Read
  }
}

PseudoTerminal::PseudoTerminal(const std::string& symlink) {
  master_fd_ = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_fd_ < 0) {
    throw HardwareError("/dev/ptmx", "cannot create a pseudo-terminal: " + Errno(errno));
  }
  try {
    if (grantpt(master_fd_) != 0 || unlockpt(master_fd_) != 0) {
      throw HardwareError("/dev/ptmx", "cannot unlock the pseudo-terminal: " + Errno(errno));
    }
    char name[PATH_MAX];
    if (ptsname_r(master_fd_, name, sizeof(name)) != 0) {
      throw HardwareError("/dev/ptmx", "cannot name the pseudo-terminal's slave: " + Errno(errno));
    }
    slave_path_ = name;
    slave_fd_ = ::open(name, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (slave_fd_ < 0) {
      throw HardwareError(slave_path_, "cannot open the pseudo-terminal's slave: " + Errno(errno));
    }
    for (int fd : {slave_fd_, master_fd_}) {
      termios tio{};
      if (tcgetattr(fd, &tio) != 0) {
        throw HardwareError(slave_path_, "tcgetattr failed: " + Errno(errno));
      }
      MakeRaw(&tio);
      if (tcsetattr(fd, TCSANOW, &tio) != 0) {
        throw HardwareError(slave_path_, "cannot set raw mode: " + Errno(errno));
      }
    }
    const int flags = fcntl(master_fd_, F_GETFL);
    if (flags < 0 || fcntl(master_fd_, F_SETFL, flags | O_NONBLOCK) != 0) {
      throw HardwareError(slave_path_, "cannot make the master non-blocking: " + Errno(errno));
    }
    if (!symlink.empty()) {
      struct stat st {};
      if (lstat(symlink.c_str(), &st) == 0) {
        if (!S_ISLNK(st.st_mode)) {
          throw HardwareError(symlink,
                              "exists and is not a symbolic link (not replacing it with a link "
                              "to the pseudo-terminal)");
        }
        if (::unlink(symlink.c_str()) != 0) {
          throw HardwareError(symlink, "cannot replace the old link: " + Errno(errno));
        }
      }
      if (::symlink(slave_path_.c_str(), symlink.c_str()) != 0) {
        throw HardwareError(symlink,
                            "cannot create a link to " + slave_path_ + ": " + Errno(errno));
      }
      link_path_ = symlink;
    }
  } catch (...) {
    Close();
    throw;
  }
}

PseudoTerminal::~PseudoTerminal() { Close(); }

PseudoTerminal::PseudoTerminal(PseudoTerminal&& other) noexcept
    : master_fd_(std::exchange(other.master_fd_, -1)),
      slave_fd_(std::exchange(other.slave_fd_, -1)),
      slave_path_(std::move(other.slave_path_)),
      link_path_(std::exchange(other.link_path_, std::string())) {}

PseudoTerminal& PseudoTerminal::operator=(PseudoTerminal&& other) noexcept {
  if (this != &other) {
    Close();
    master_fd_ = std::exchange(other.master_fd_, -1);
    slave_fd_ = std::exchange(other.slave_fd_, -1);
    slave_path_ = std::move(other.slave_path_);
    link_path_ = std::exchange(other.link_path_, std::string());
  }
  return *this;
}

void PseudoTerminal::Close() noexcept {
  if (!link_path_.empty()) {
    // Remove the link only while it still points to this pseudo-terminal: another
    // emulator may have taken the name since.
    char target[PATH_MAX];
    const ssize_t n = ::readlink(link_path_.c_str(), target, sizeof(target) - 1);
    if (n >= 0 && std::string(target, static_cast<size_t>(n)) == slave_path_) {
      ::unlink(link_path_.c_str());
    }
    link_path_.clear();
  }
  if (slave_fd_ >= 0) ::close(slave_fd_);
  if (master_fd_ >= 0) ::close(master_fd_);
  slave_fd_ = -1;
  master_fd_ = -1;
}

}  // namespace saccade::hw
