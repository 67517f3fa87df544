#pragma once
// The calibrated matrix K as an OpenGL projection matrix, and back (seed section 4.1).
//
// OpenGL's eye frame is x right, y up, z backward; the optical frame (intrinsics.h) is
// x right, y down, z forward, so p_eye = (X, -Y, -Z). OpenGL's window coordinates put the
// origin at the bottom-left corner of the bottom-left pixel, whose centre is (0.5, 0.5);
// OpenCV puts the centre of the top-left pixel at (0, 0). Hence, for a viewport of
// width x height:
//   u = x_window - 0.5,   v = height - y_window - 0.5.
// The matrix below makes a point rendered through it land exactly on the pixel
// cv::projectPoints gives (no distortion), with
//   P = [ 2fx/w   -2s/w   (w - 2cx - 1)/w      0     ]
//       [   0     2fy/h   (2cy + 1 - h)/h      0     ]
//       [   0       0     -(f + n)/(f - n)  -2fn/(f - n) ]
//   and P(3,2) = -1, acting on p_eye.
// With flip_rows = true, row 1 is negated: the framebuffer's row 0 is then the image's top
// row, which flips the image on the GPU at no cost (front faces change winding).

#include <Eigen/Core>

#include "saccade/geometry/intrinsics.h"

namespace saccade::geometry {

/// Depth range of the OpenGL frustum, in metres: 0 < near < far, both finite.
struct ClipPlanes {
  double near = 0.01;
  double far = 100.0;
};

/// The 4x4 OpenGL projection for K and the clip planes (column vectors, acting on p_eye).
/// Throws InvalidArgument when the clip planes are not 0 < near < far < inf.
Eigen::Matrix4d GlProjectionFromIntrinsics(const Intrinsics& intrinsics, const ClipPlanes& clip,
                                           bool flip_rows = false);

/// K back from an OpenGL projection matrix and its viewport size (the inverse of the above;
/// `flip_rows` says whether row 1 was negated). Throws InvalidArgument when the matrix is not
/// a perspective projection of that form (P(3,2) != -1, non-zero where zeros belong, ...).
Intrinsics IntrinsicsFromGlProjection(const Eigen::Matrix4d& projection, int width, int height,
                                      bool flip_rows = false);

/// The clip planes encoded in a projection made by GlProjectionFromIntrinsics.
ClipPlanes ClipPlanesFromGlProjection(const Eigen::Matrix4d& projection);

/// Rotation from the optical frame to OpenGL's eye frame: diag(1, -1, -1).
Eigen::Matrix3d OpticalToGlEye();

/// Pixel (u, v) (OpenCV convention) of OpenGL window coordinates (x, y), and back.
Eigen::Vector2d WindowToPixel(const Eigen::Vector2d& window, int height);
Eigen::Vector2d PixelToWindow(const Eigen::Vector2d& pixel, int height);

}  // namespace saccade::geometry
