#include "saccade/head/report.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cmath>

#include "saccade/core/error.h"
#include "saccade/core/units.h"
#include "saccade/geometry/json.h"
#include "saccade/head/json.h"

namespace saccade::head {
namespace {

using nlohmann::json;

JointState Degrees(const JointState& q) {
  return {q.pan * kRadToDeg, q.tilt * kRadToDeg, q.left * kRadToDeg, q.right * kRadToDeg};
}

std::string FormatVector(const Eigen::Vector3d& v) {
  return fmt::format("[{:+.6f}, {:+.6f}, {:+.6f}]", v.x(), v.y(), v.z());
}

std::string FormatJointsDeg(const JointState& q) {
  const JointState d = Degrees(q);
  return fmt::format("pan {:+.4f}  tilt {:+.4f}  left {:+.4f}  right {:+.4f}  (deg)", d.pan, d.tilt,
                     d.left, d.right);
}

std::string FormatPose(const char* name, const geometry::Pose& X) {
  return fmt::format("  {:<14} position {} m   optical axis {}\n", name,
                     FormatVector(X.translation()), FormatVector(X.linear().col(2)));
}

}  // namespace

json PoseReadableJson(const geometry::Pose& X) {
  json rotation = json::array();
  for (int r = 0; r < 3; ++r) rotation.push_back({X(r, 0), X(r, 1), X(r, 2)});
  const Eigen::Quaterniond q(X.linear());
  return {{"position", ToJson<Eigen::Vector3d>(X.translation())},
          {"rotation", rotation},
          {"quaternion_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

json FkReportJson(const HeadDescription& head, const JointState& q) {
  const HeadFrames frames = ForwardKinematics(head, q);
  return {{"head", head.name()},
          {"joints", ToJson(q)},
          {"within_limits", head.WithinLimits(q)},
          {"cameras",
           {{"left", PoseReadableJson(frames.X_WCamLeft)},
            {"right", PoseReadableJson(frames.X_WCamRight)}}},
          {"fixation",
           frames.p_WFixation ? ToJson<Eigen::Vector3d>(*frames.p_WFixation) : json(nullptr)}};
}

std::string FkReportText(const HeadDescription& head, const JointState& q) {
  const HeadFrames frames = ForwardKinematics(head, q);
  std::string out = fmt::format("joints: {}\n", FormatJointsDeg(q));
  if (!head.WithinLimits(q)) {
    try {
      head.CheckLimits(q);
    } catch (const Error& e) {
      out += fmt::format("warning: {}\n", e.what());
    }
  }
  out += FormatPose("left camera", frames.X_WCamLeft);
  out += FormatPose("right camera", frames.X_WCamRight);
  if (frames.p_WFixation) {
    out += fmt::format("  fixation       {} m\n", FormatVector(*frames.p_WFixation));
  } else {
    out += "  fixation       none (optical axes parallel or diverging)\n";
  }
  return out;
}

json IkReportJson(const HeadDescription& head, const Eigen::Vector3d& p_W, const std::string& mode,
                  const IkResult& result) {
  return {{"head", head.name()},
          {"target", ToJson<Eigen::Vector3d>(p_W)},
          {"mode", mode},
          {"reachable", result.reachable()},
          {"reachability", ToString(result.reachability)},
          {"message", result.message},
          {"joints", ToJson(result.joints)},
          {"joints_deg", ToJson(Degrees(result.joints))},
          {"axis_error_rad", result.axis_error},
          {"iterations", result.iterations}};
}

std::string IkReportText(const Eigen::Vector3d& p_W, const IkResult& result) {
  std::string out = fmt::format("target {} m in the world\n", FormatVector(p_W));
  out += fmt::format("joints: {}\n", FormatJointsDeg(result.joints));
  if (result.reachable()) {
    out += fmt::format(
        "reachable: both optical axes pass through the target (axis error {:.2e} rad, "
        "{} iterations)\n",
        result.axis_error, result.iterations);
  } else {
    out += fmt::format(
        "NOT reachable ({}): {}\n  the joints above are the nearest reachable "
        "(axis error {:.4f} deg)\n",
        ToString(result.reachability), result.message, result.axis_error * kRadToDeg);
  }
  return out;
}

}  // namespace saccade::head
