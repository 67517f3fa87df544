#pragma once
// Errors of the real robot's devices (DESIGN.md: `hw`): a serial port, a servo bus, a camera.
// Every message names the device ("/dev/ttyUSB0", "servo 3 (tilt)", "camera left") and
// what went wrong, so that an operator can find the cable, the servo or the file.

#include <string>

#include "saccade/core/error.h"

namespace saccade::hw {

/// A device that cannot be opened, read or written, or that answers wrongly.
class HardwareError : public Error {
 public:
  /// The message is "<device>: <what>".
  HardwareError(const std::string& device, const std::string& what);
  const std::string& device() const { return device_; }

 private:
  std::string device_;
};

}  // namespace saccade::hw
