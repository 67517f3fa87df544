#pragma once
// What `saccade fk` and `saccade ik` print: a solution of the head's kinematics as JSON for
// scripts (docs/cli.md, a stable interface) and as text for people.
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

#include "saccade/geometry/pose.h"
#include "saccade/head/fixation.h"
#include "saccade/head/head_description.h"
#include "saccade/head/head_model.h"
#include "saccade/head/kinematics.h"

namespace saccade::head {

/// {"position": [...], "rotation": [[...] x 3], "quaternion_wxyz": [...]}: a pose for people
/// (the 4x4 matrix is its codec's form, geometry/json.h).
nlohmann::json PoseReadableJson(const geometry::Pose& X);

/// Forward kinematics at `q`: the joints, whether they are within the limits, both cameras'
/// poses and the fixation point.
nlohmann::json FkReportJson(const HeadDescription& head, const PopeyeJoints& q);
std::string FkReportText(const HeadDescription& head, const PopeyeJoints& q);

/// Any head (head_model.h): the joints by name, within limits, both cameras' poses and where
/// the optical axes meet (fixation.h's FixationPoint).
nlohmann::json FkReportJson(const HeadModel& head, const JointState& q);
std::string FkReportText(const HeadModel& head, const JointState& q);
/// Any head's fixation (fixation.h) of `p_W`.
nlohmann::json IkReportJson(const HeadModel& head, const Eigen::Vector3d& p_W,
                            const FixationResult& result);
std::string IkReportText(const HeadModel& head, const Eigen::Vector3d& p_W,
                         const FixationResult& result);

/// An inverse-kinematics solution for the target `p_W`, solved in `mode` (its name).
nlohmann::json IkReportJson(const HeadDescription& head, const Eigen::Vector3d& p_W,
                            const std::string& mode, const IkResult& result);
std::string IkReportText(const Eigen::Vector3d& p_W, const IkResult& result);

}  // namespace saccade::head
