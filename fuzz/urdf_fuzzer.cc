// libFuzzer target: URDF text (issue 42) -> head::ParseUrdf, urdfdom and TinyXML underneath,
// with Gazebo's camera blocks. Bad input must end in a saccade::Error (a FileError naming the
// file, the element and what was expected); anything else escaping (urdfdom's or TinyXML's own
// exceptions, std::out_of_range, ...) is a bug. A model that loads must be a valid tree: at
// least one link, every joint's parent and child a link, every variable an actuated joint, a
// mimic following a variable; forward kinematics at the home posture (0 clamped into each
// joint's limits) finite with orthonormal rotations; every camera on an existing link with a
// model that builds (GazeboCamera::Model must not throw for a camera the loader accepted) and a
// finite optical frame. Meshes are optional (visuals_optional), so a missing mesh is a warning.
// Built and run by fuzz/run.sh.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "fuzz_checks.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"
#include "saccade/head/urdf.h"

namespace head = saccade::head;

namespace {

constexpr std::size_t kMaxInput = 32 * 1024;

using saccade::fuzz::Check;
using saccade::fuzz::CheckPose;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  saccade::log::SetLevel(saccade::log::Level::kOff);  // missing meshes warn on every input
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size > kMaxInput) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  head::UrdfOptions options;
  options.visuals_optional = true;
  std::optional<head::UrdfModel> loaded;
  try {
    loaded.emplace(head::ParseUrdf(text, "fuzz.urdf", ".", options));
  } catch (const saccade::Error&) {
    return 0;  // rejected with a message: the expected outcome for bad input
  }
  const head::KinematicTree& tree = loaded->tree;
  Check(tree.num_links() >= 1);
  Check(tree.root() >= 0 && tree.root() < tree.num_links());
  Check(tree.parent_joint(tree.root()) == -1);
  for (int j = 0; j < tree.num_joints(); ++j) {
    const head::KinematicTree::Joint& joint = tree.joint(j);
    Check(joint.parent >= 0 && joint.parent < tree.num_links());
    Check(joint.child >= 0 && joint.child < tree.num_links());
    Check(tree.parent_joint(joint.child) == j);
    Check(joint.variable >= -1 && joint.variable < tree.num_variables());
    Check(joint.moves() == (joint.type != head::JointType::kFixed));
    Check(std::abs(joint.axis.norm() - 1.0) < 1e-12);
  }
  for (int v = 0; v < tree.num_variables(); ++v) {
    const head::KinematicTree::Joint& joint = tree.joint(tree.variable_joint(v));
    Check(!joint.is_mimic && joint.variable == v);
  }
  Eigen::VectorXd q(tree.num_variables());
  for (int v = 0; v < q.size(); ++v) {
    const head::KinematicTree::Joint& joint = tree.joint(tree.variable_joint(v));
    Check(joint.lower <= joint.upper);
    q[v] = std::clamp(0.0, joint.lower, joint.upper);
    if (!std::isfinite(q[v])) q[v] = 0.0;  // a huge but finite limit is fine; inf is not a value
  }
  std::vector<saccade::geometry::Pose> X_WL;
  tree.ForwardKinematics(q, saccade::geometry::Pose::Identity(), &X_WL);
  Check(static_cast<int>(X_WL.size()) == tree.num_links());
  // Origins of ~1e300 m are finite in the file and overflow when added: only check trees whose
  // every number is of a sensible size (a head is metres, not light years).
  bool sensible = true;
  for (int j = 0; j < tree.num_joints(); ++j) {
    const head::KinematicTree::Joint& joint = tree.joint(j);
    sensible = sensible && joint.X_PJ.translation().cwiseAbs().maxCoeff() < 1e6 &&
               std::abs(tree.JointValue(j, q)) < 1e6;
  }
  if (sensible) {
    for (const saccade::geometry::Pose& X : X_WL) CheckPose(X);
  }
  for (const head::GazeboCamera& camera : loaded->cameras) {
    Check(camera.link_index >= 0 && camera.link_index < tree.num_links());
    Check(tree.link_name(camera.link_index) == camera.link);
    (void)camera.Model();  // throws, and is reported, if the loader let a bad camera through
    if (camera.X_LS.translation().cwiseAbs().maxCoeff() < 1e6) CheckPose(camera.X_LOptical());
  }
  return 0;
}
