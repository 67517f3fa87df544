#include <filesystem>

#include "commands.h"

namespace saccade::app {

std::string ShippedFile(const std::string& relative) {
  namespace fs = std::filesystem;
  if (fs::exists(relative)) return relative;
  // The source tree it was built from; else where `cmake --install` put the data.
  const fs::path source = fs::path(SACCADE_SOURCE_DIR) / relative;
  const fs::path installed = fs::path(SACCADE_DATA_DIR) / relative;
  if (!fs::exists(source) && fs::exists(installed)) return installed.string();
  return source.string();
}

head::JointState JointsFromArgs(const std::vector<double>& values, bool degrees) {
  const double s = degrees ? kDegToRad : 1.0;
  return {values[0] * s, values[1] * s, values[2] * s, values[3] * s};
}

}  // namespace saccade::app
