#include "saccade/hw/hw_error.h"

namespace saccade::hw {

HardwareError::HardwareError(const std::string& device, const std::string& what)
    : Error(device + ": " + what), device_(device) {}

}  // namespace saccade::hw
