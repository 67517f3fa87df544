#include "saccade/components/accommodation_component.h"

#include <fmt/format.h>

#include <algorithm>

#include "saccade/core/error.h"
#include "saccade/geometry/image_camera.h"
#include "saccade/head/fixation.h"

namespace saccade::components {

AccommodationComponent::AccommodationComponent()
    : left_(AddInput<runtime::ImageMessage>("left", /*required=*/true)),
      right_(AddInput<runtime::ImageMessage>("right", /*required=*/true)),
      upstream_(AddInput<CameraControlsMessage>("controls")),
      controls_(AddOutput<CameraControlsMessage>("controls")) {
  DeclareParam("min_focus_m", &min_focus_m_, "the nearest focus distance commanded")
      .Range(1e-3, 1e6)
      .Unit("m");
  DeclareParam("max_focus_m", &max_focus_m_,
               "the farthest focus distance commanded: where parallel axes focus")
      .Range(1e-3, 1e6)
      .Unit("m");
}

void AccommodationComponent::Configured() {
  if (min_focus_m_ > max_focus_m_) {
    throw InvalidArgument(
        fmt::format("parameter 'min_focus_m': expected at most max_focus_m ({} m), got {} m",
                    max_focus_m_, min_focus_m_));
  }
}

Eigen::Vector2d AccommodationComponent::FocusDistances(const geometry::Pose& X_WLeft,
                                                       const geometry::Pose& X_WRight,
                                                       double min_focus_m, double max_focus_m) {
  const std::optional<Eigen::Vector3d> p_W = head::FixationPoint(X_WLeft, X_WRight);
  if (!p_W) return {max_focus_m, max_focus_m};
  Eigen::Vector2d focus;
  int eye = 0;
  for (const geometry::Pose* X_WC : {&X_WLeft, &X_WRight}) {
    const double depth = (*p_W - X_WC->translation()).dot(X_WC->linear().col(2));
    focus[eye++] = std::clamp(depth, min_focus_m, max_focus_m);
  }
  return focus;
}

void AccommodationComponent::Step(const runtime::StepContext& context) {
  const runtime::ImageMessage* left = left_.get();
  const runtime::ImageMessage* right = right_.get();
  const CameraControlsMessage* upstream = upstream_.fresh() ? upstream_.get() : nullptr;
  CameraControlsMessage out;
  out.time = context.time;
  if (upstream != nullptr) out.commands = upstream->commands;
  if (left != nullptr && right != nullptr && left->image && right->image &&
      (left_.fresh() || right_.fresh())) {
    const geometry::Pose* X_WLeft = geometry::FindCameraPose(left->image->metadata());
    const geometry::Pose* X_WRight = geometry::FindCameraPose(right->image->metadata());
    if (X_WLeft == nullptr || X_WRight == nullptr) {
      throw InvalidArgument(fmt::format(
          "{}: inputs 'left' and 'right': the images carry no camera pose (X_WC in their "
          "metadata); accommodation needs both",
          name()));
    }
    const Eigen::Vector2d focus = FocusDistances(*X_WLeft, *X_WRight, min_focus_m_, max_focus_m_);
    out.commands.push_back({left->image->metadata().camera, {}, {}, focus[0]});
    out.commands.push_back({right->image->metadata().camera, {}, {}, focus[1]});
  }
  if (!out.commands.empty()) controls_.Emit(out);
}

}  // namespace saccade::components
