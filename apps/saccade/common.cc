#include <filesystem>

#include "commands.h"

namespace saccade::app {

using nlohmann::json;

std::string ShippedFile(const std::string& relative) {
  namespace fs = std::filesystem;
  if (fs::exists(relative)) return relative;
  // The source tree it was built from; else where `cmake --install` put the data.
  const fs::path source = fs::path(SACCADE_SOURCE_DIR) / relative;
  const fs::path installed = fs::path(SACCADE_DATA_DIR) / relative;
  if (!fs::exists(source) && fs::exists(installed)) return installed.string();
  return source.string();
}

json PoseJson(const geometry::Pose& X) {
  json rotation = json::array();
  for (int r = 0; r < 3; ++r) rotation.push_back({X(r, 0), X(r, 1), X(r, 2)});
  const Eigen::Quaterniond q(X.linear());
  return {{"position", ToJson<Eigen::Vector3d>(X.translation())},
          {"rotation", rotation},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

head::JointState JointsFromArgs(const std::vector<double>& values, bool degrees) {
  const double s = degrees ? kDegToRad : 1.0;
  return {values[0] * s, values[1] * s, values[2] * s, values[3] * s};
}

}  // namespace saccade::app
