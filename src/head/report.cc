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

PopeyeJoints Degrees(const PopeyeJoints& q) {
  return {q.pan * kRadToDeg, q.tilt * kRadToDeg, q.left * kRadToDeg, q.right * kRadToDeg};
}

JointState ToJointState(const PopeyeJoints& q) {
  return JointState::Popeye(q.pan, q.tilt, q.left, q.right);
}

std::string FormatVector(const Eigen::Vector3d& v) {
  return fmt::format("[{:+.6f}, {:+.6f}, {:+.6f}]", v.x(), v.y(), v.z());
}

std::string FormatJointsDeg(const PopeyeJoints& q) {
  const PopeyeJoints d = Degrees(q);
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

json FkReportJson(const HeadDescription& head, const PopeyeJoints& q) {
  const HeadFrames frames = ForwardKinematics(head, q);
  return {{"head", head.name()},
          {"joints", ToJson(ToJointState(q))},
          {"within_limits", head.WithinLimits(q)},
          {"cameras",
           {{"left", PoseReadableJson(frames.X_WCamLeft)},
            {"right", PoseReadableJson(frames.X_WCamRight)}}},
          {"fixation",
           frames.p_WFixation ? ToJson<Eigen::Vector3d>(*frames.p_WFixation) : json(nullptr)}};
}

std::string FkReportText(const HeadDescription& head, const PopeyeJoints& q) {
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

namespace {

bool Angular(const HeadModel& head, int joint) {
  return head.tree().joint(head.tree().variable_joint(joint)).type != JointType::kPrismatic;
}

// "neck_yaw +12.0000 deg  left_eye_pan -3.0000 deg ..."
std::string FormatJoints(const HeadModel& head, const JointState& q) {
  std::string out;
  for (int i = 0; i < q.size(); ++i) {
    const bool angular = Angular(head, i);
    out += fmt::format("{}{} {:+.4f} {}", out.empty() ? "" : "  ", q.name(i),
                       q[i] * (angular ? kRadToDeg : 1.0), angular ? "deg" : "m");
  }
  return out;
}

json Degrees(const HeadModel& head, const JointState& q) {
  json out = json::object();
  for (int i = 0; i < q.size(); ++i) out[q.name(i)] = q[i] * (Angular(head, i) ? kRadToDeg : 1.0);
  return out;
}

}  // namespace

json FkReportJson(const HeadModel& head, const JointState& q) {
  const std::array<geometry::Pose, 2> cameras = head.CameraPoses(q);
  const auto fixation = FixationPoint(cameras[0], cameras[1]);
  return {{"head", head.name()},
          {"joints", ToJson(q)},
          {"within_limits", head.WithinLimits(head.Arrange(q).values())},
          {"cameras",
           {{"left", PoseReadableJson(cameras[0])}, {"right", PoseReadableJson(cameras[1])}}},
          {"fixation", fixation ? ToJson<Eigen::Vector3d>(*fixation) : json(nullptr)}};
}

std::string FkReportText(const HeadModel& head, const JointState& q) {
  const std::array<geometry::Pose, 2> cameras = head.CameraPoses(q);
  std::string out = fmt::format("joints: {}\n", FormatJoints(head, q));
  try {
    head.CheckLimits(head.Arrange(q).values());
  } catch (const Error& e) {
    out += fmt::format("warning: {}\n", e.what());
  }
  out += FormatPose("left camera", cameras[0]);
  out += FormatPose("right camera", cameras[1]);
  if (const auto fixation = FixationPoint(cameras[0], cameras[1])) {
    out += fmt::format("  fixation       {} m\n", FormatVector(*fixation));
  } else {
    out += "  fixation       none (optical axes parallel or diverging)\n";
  }
  return out;
}

json IkReportJson(const HeadModel& head, const Eigen::Vector3d& p_W, const FixationResult& result) {
  const JointState q = head.State(result.joints);
  return {{"head", head.name()},
          {"target", ToJson<Eigen::Vector3d>(p_W)},
          {"mode", result.mid_axis ? "mid-axis" : "both axes"},
          {"reachable", result.reachable()},
          {"reachability", ToString(result.reachability)},
          {"message", result.message},
          {"joints", ToJson(q)},
          {"joints_deg", Degrees(head, q)},
          {"axis_error_rad", result.axis_error},
          {"iterations", result.iterations}};
}

std::string IkReportText(const HeadModel& head, const Eigen::Vector3d& p_W,
                         const FixationResult& result) {
  std::string out = fmt::format("target {} m in the world\n", FormatVector(p_W));
  out += fmt::format("joints: {}\n", FormatJoints(head, head.State(result.joints)));
  if (result.reachable()) {
    out += fmt::format(
        "reachable: {} through the target (axis error {:.2e} rad, {} iterations)\n",
        result.mid_axis ? "the axis midway between the cameras passes" : "both optical axes pass",
        result.axis_error, result.iterations);
  } else {
    out += fmt::format(
        "NOT reachable ({}): {}\n  the joints above are the best found within the limits (axis "
        "error {:.4f} deg)\n",
        ToString(result.reachability), result.message, result.axis_error * kRadToDeg);
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
          {"joints", ToJson(ToJointState(result.joints))},
          {"joints_deg", ToJson(ToJointState(Degrees(result.joints)))},
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
