#pragma once
// The checks the head fuzzers (head, head_model, urdf) share: a failed one aborts, and libFuzzer
// reports it with the input.
#include <Eigen/Core>
#include <cstdlib>

#include "saccade/geometry/pose.h"

namespace saccade::fuzz {

inline void Check(bool condition) {
  if (!condition) std::abort();
}

// Finite, with a rotation whose columns are orthonormal (to what double rounding allows).
inline void CheckPose(const geometry::Pose& X) {
  const Eigen::Matrix4d m = X.matrix();
  Check(m.allFinite());
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  Check((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-9);
}

}  // namespace saccade::fuzz
