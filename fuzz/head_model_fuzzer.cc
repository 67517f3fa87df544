// libFuzzer target: head files of either format (issue 42) -> head::HeadModel::FromYamlString,
// with relative paths under $SACCADE_FUZZ_ROBOTS_DIR (run.sh: the repository's robots/), so
// `urdf: humanoid/humanoid.urdf` and `calibration:` files resolve to the shipped ones. A
// target of its own beside head_fuzzer: that one checks what only the legacy
// HeadDescription has (its validating constructor, servo inversion, appendix A), this one what
// every HeadModel must hold. Bad input must end in a saccade::Error; anything else escaping
// (yaml-cpp's exceptions, std::out_of_range, ...) is a bug. A head that loads must have a
// setting per actuated joint with min <= max and the home posture within its limits, both
// cameras on existing links, a fixation rule sized to the joints with weights > 0 and valid
// pairs, and finite forward kinematics with orthonormal rotations at home. Built and run by
// fuzz/run.sh.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fuzz_checks.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"
#include "saccade/head/head_model.h"

namespace head = saccade::head;

namespace {

constexpr std::size_t kMaxInput = 16 * 1024;

using saccade::fuzz::Check;
using saccade::fuzz::CheckPose;

std::filesystem::path RobotsDir() {
  const char* env = std::getenv("SACCADE_FUZZ_ROBOTS_DIR");
  return env ? env : "robots";
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  saccade::log::SetLevel(saccade::log::Level::kOff);  // `visuals: optional` warns per mesh
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size > kMaxInput) return 0;
  static const std::filesystem::path robots = RobotsDir();
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::optional<head::HeadModel> loaded;
  try {
    loaded.emplace(head::HeadModel::FromYamlString(text, "fuzz.yaml", robots));
  } catch (const saccade::Error&) {
    return 0;  // rejected with a message: the expected outcome for bad input
  }
  const head::HeadModel& h = *loaded;
  const head::KinematicTree& tree = h.tree();
  Check(h.num_joints() == tree.num_variables());
  for (int i = 0; i < h.num_joints(); ++i) {
    const head::JointSettings& s = h.joint(i);
    Check(s.limits.min <= s.limits.max);
    Check(!s.driven || (s.limits.max_velocity > 0.0 && s.limits.max_acceleration > 0.0));
    Check(s.driven || s.limits.Contains(s.hold));
  }
  const Eigen::VectorXd home = h.HomePosture();
  Check(home.size() == h.num_joints() && h.WithinLimits(home));
  for (int eye = 0; eye < 2; ++eye) {
    Check(h.camera(eye).link >= 0 && h.camera(eye).link < tree.num_links());
  }
  const head::FixationRule& rule = h.fixation_rule();
  Check(static_cast<int>(rule.hold.size()) == h.num_joints());
  Check(rule.weights.size() == h.num_joints() && rule.preferred.size() == h.num_joints());
  for (int i = 0; i < h.num_joints(); ++i) Check(rule.weights[i] > 0.0);
  for (const head::FixationRule::Pair& p : rule.symmetric) {
    Check(p.a >= 0 && p.a < h.num_joints() && p.b >= 0 && p.b < h.num_joints() && p.a != p.b);
  }
  // Finite poses for a head of sensible size (a base a million metres away is finite in the
  // file and loses its rotation's orthonormality to rounding when added to).
  if (h.X_WB().translation().cwiseAbs().maxCoeff() < 1e6 && home.cwiseAbs().maxCoeff() < 1e6) {
    std::vector<saccade::geometry::Pose> X_WL;
    h.ForwardKinematics(home, &X_WL);
    for (const saccade::geometry::Pose& X : X_WL) CheckPose(X);
    for (int eye = 0; eye < 2; ++eye) CheckPose(h.CameraPose(eye, X_WL));
  }
  return 0;
}
