#pragma once
// Reading the camera model a frame carries (geometry/image_camera.h) in tests: its distortion
// model's name, its coefficients and K's entries, or a failing value when it carries none.
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/geometry/image_camera.h"

namespace saccade::testing_helpers {

inline std::string DistortionName(const ImageMetadata& m) {
  const geometry::CameraModel* c = geometry::FindCameraModel(m);
  return c ? geometry::ToString(c->distortion().model()) : "(no camera model)";
}
inline std::vector<double> Coefficients(const ImageMetadata& m) {
  const geometry::CameraModel* c = geometry::FindCameraModel(m);
  return c ? c->distortion().coefficients() : std::vector<double>{-1.0};
}
/// K(k / 3, k % 3); NaN when the frame carries no camera model.
inline double KAt(const ImageMetadata& m, int k) {
  const geometry::CameraModel* c = geometry::FindCameraModel(m);
  return c ? c->intrinsics().Matrix()(k / 3, k % 3) : std::nan("");
}

}  // namespace saccade::testing_helpers
