#pragma once
// The depth of field's depth from the colour pass's own depth buffer (EffectTarget::
// ReadColorDepth), for a camera whose only need of depth is its depth of field, on a software
// rasteriser: the truth pass draws the scene a second time and its remap pass fetches nine
// texels a pixel, together about 80 ms a stereo frame of the bench scene on llvmpipe, while
// the colour pass has already rasterised the depth. Here the window depth becomes the
// camera's z on the CPU (the projection's inverse along each pixel's ray) and is remapped
// through the lens as the truth's is (CpuLens::RemapDepthRow). The colour pass's depth is
// that of the sub-frame drawn first (the exposure's middle, or its middle stretch), as the
// truth pass's is the frame's instant.

#include <Eigen/Core>
#include <vector>

#include "saccade/geometry/intrinsics.h"

namespace saccade::render::gl {

/// How a view's window depth d becomes the camera's z: the depth along the view's axis
/// D = b / (2 d - 1 + a) (the projection's P(2, 2) = a and P(2, 3) = b, depth range [0, 1]),
/// and the camera's z = D (column[u] + row[v]) at source pixel (u, v) (the ray
/// ((u - cx) / fx, (v - cy) / fy, 1) of the view turned by R_CV, its z).
struct ColorDepthMap {
  double a = 0.0, b = 0.0;
  std::vector<float> column, row;
};

ColorDepthMap MakeColorDepthMap(const Eigen::Matrix4d& projection, const Eigen::Matrix3d& R_CV,
                                const geometry::Intrinsics& source);

/// Source rows [first_row, end_row) of `window_depth` (source-size floats, row 0 at the
/// image's top, as read back) into the camera's z, 0 where nothing was drawn (d = 1). Four
/// pixels at a time with AVX where the CPU has it and `simd` is true: the same operations in
/// double and float lane by lane (no fused multiply-add), the same bits.
void CameraZRows(const ColorDepthMap& map, const float* window_depth, int first_row, int end_row,
                 float* camera_z, bool simd = true);

}  // namespace saccade::render::gl
