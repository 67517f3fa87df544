// libFuzzer target: head description YAML (robots/popeye.yaml documents the format) ->
// head::HeadDescription::FromYamlString. Bad input must end in a saccade::Error (a FileError
// naming file, line and key); anything else escaping is a bug. A head that loads must pass
// its own validating constructor again with the values it holds (the loader checks no less
// than the constructor), its servo mappings must invert (JointAngle of ServoAngle), and
// forward kinematics at zero and at its limits' corners must give finite, orthonormal poses.
// Built and run by fuzz/run.sh.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>

#include "fuzz_checks.h"
#include "saccade/core/error.h"
#include "saccade/head/head_description.h"
#include "saccade/head/kinematics.h"

namespace head = saccade::head;

namespace {

constexpr std::size_t kMaxInput = 16 * 1024;

using saccade::fuzz::Check;
using saccade::fuzz::CheckPose;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size > kMaxInput) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::optional<head::HeadDescription> loaded;
  try {
    loaded.emplace(head::HeadDescription::FromYamlString(text, "fuzz.yaml"));
  } catch (const saccade::Error&) {
    return 0;  // rejected with a message: the expected outcome for bad input
  }
  const head::HeadDescription& h = *loaded;
  std::array<head::JointLimits, 4> limits;
  std::array<std::optional<head::ServoMapping>, 4> servos;
  for (const head::Joint joint : head::kAllJoints) {
    limits[static_cast<int>(joint)] = h.limits(joint);
    servos[static_cast<int>(joint)] = h.servo(joint);
  }
  // The constructor must accept what the loader accepted (it throws InvalidArgument, which
  // escapes and is reported, when the loader let something through that it forbids).
  const head::HeadDescription rebuilt(h.name(), h.geometry(), limits, h.X_WB(), h.left_camera(),
                                      h.right_camera(), servos);
  Check(rebuilt.left_camera() == h.left_camera() && rebuilt.right_camera() == h.right_camera());

  for (const head::Joint joint : head::kAllJoints) {
    const head::JointLimits& l = h.limits(joint);
    Check(l.min <= 0.0 && l.max >= 0.0 && l.max_velocity > 0.0 && l.max_acceleration > 0.0);
    if (const auto& servo = h.servo(joint)) {
      for (const double q : {0.0, l.min, l.max}) {
        if (!std::isfinite(q) || std::abs(q) > 1e3) continue;
        const double back = servo->JointAngle(servo->ServoAngle(q));
        Check(std::abs(back - q) <=
              1e-9 * (1.0 + std::abs(q)) * (1.0 + servo->gear_ratio + 1.0 / servo->gear_ratio) +
                  1e-12 * std::abs(servo->zero_offset));
      }
    }
  }
  // Forward kinematics at zero and at the corners of the limits (clamped to a turn).
  const auto clamp = [](double v) { return std::max(-M_PI, std::min(M_PI, v)); };
  for (int corner = 0; corner < 17; ++corner) {
    head::PopeyeJoints q;
    if (corner < 16) {
      for (const head::Joint joint : head::kAllJoints) {
        const int bit = 1 << static_cast<int>(joint);
        q[joint] = clamp((corner & bit) ? h.limits(joint).max : h.limits(joint).min);
      }
    }
    const head::HeadFrames frames = head::ForwardKinematics(h, q);
    for (const auto* X : {&frames.X_WB, &frames.X_WN, &frames.X_WC, &frames.X_WL, &frames.X_WR,
                          &frames.X_WCamLeft, &frames.X_WCamRight}) {
      CheckPose(*X);
    }
  }
  return 0;
}
