#pragma once
// How a renderer makes a distorted image: it draws one or more ideal pinhole "source views"
// that share the camera's centre of projection, then fetches, for every pixel of the
// distorted image, the source pixel that sees the same ray (DESIGN.md: the simulator's pixels
// land where cv::projectPoints / cv::fisheye::projectPoints put them).
//
// - kIdentity: no distortion. One view, the camera itself; the map is the identity and a
//   renderer may skip the remap.
// - kPinhole: one view with the camera's orientation, rendered wider than the image (its
//   intrinsics cover every ray the distorted image sees, plus a margin) and, where the lens
//   magnifies (pincushion), at a finer pixel pitch, so that no output pixel magnifies the
//   source by more than the options allow.
// - kCube: rays up to and beyond 90 degrees from the axis (wide fisheye lenses, > 120 degree
//   field of view): up to six square views of a cube around the camera, each a little wider
//   than 90 degrees (a margin on every side, so bilinear lookups near a face's edge read
//   rendered pixels), only those faces that some pixel's ray falls on. Also the fallback
//   when a single pinhole view would exceed max_source_side.
//
// Sizes (lens_map.cc states the rules in full). kPinhole: focal lengths s fx, s fy and skew
// s skew, s in [1, max_supersampling] the smallest with no magnification of the source; the
// view is the bounding box of the source points plus margin_px on every side. kCube: faces in
// the order +z, -z, +x, -x, +y, -y of C (a ray belongs to the face of its largest component),
// all S x S with c = (S - 1) / 2 and f = (S - 1) / 2 - margin_px, so that the 90-degree edges
// lie margin_px pixels inside the outermost pixel centres. The side faces and the back face
// keep y_V = y_C; the +y face has y_V = -z_C, the -y face y_V = +z_C.
//
// Conventions are those of intrinsics.h: optical frames x right, y down, z forward; pixel
// centres at integer coordinates. The map is what cv::undistortPoints would give with each
// view's matrix as P, but computed with a convergence check, so that every valid entry
// reprojects through the camera model onto its own pixel centre.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/intrinsics.h"

namespace saccade::geometry {

/// One pinhole view a renderer draws for a distorted camera.
struct SourceView {
  /// Orientation of the view's optical frame V in the camera's optical frame C (rotation only:
  /// both share the centre of projection). Identity for kIdentity and kPinhole.
  Eigen::Matrix3d R_CV = Eigen::Matrix3d::Identity();
  /// The view's pinhole intrinsics and image size (no distortion).
  Intrinsics intrinsics;
};

/// Options of MakeLensMap. Defaults in-class; IsValid says what is wrong.
struct LensMapOptions {
  /// Largest angle (radians) between a pixel's ray and the optical axis that a single pinhole
  /// view may cover; beyond it the cube is used. In (0, pi/2). Default 60 degrees (a 120
  /// degree field of view), where a pinhole view is already 3.5 focal lengths wide.
  double max_pinhole_angle = 1.0471975511965976;
  /// The source views' pixel pitch is chosen so that, over the whole image, one output pixel
  /// step spans at least one source pixel (no magnification of the source), but the source
  /// is never finer than this many times the camera's own focal length. >= 1.
  double max_supersampling = 2.0;
  /// Largest side of a source view in pixels (a GPU texture limit); a pinhole view that would
  /// be larger falls back to the cube, a cube face is capped to it (then min_scale < 1). >= 16.
  int max_source_side = 8192;
  /// Margin in pixels around what the image sees (kPinhole) and beyond 90 degrees on each
  /// side of a cube face (kCube). In [1, max_source_side / 4].
  int margin_px = 2;
  bool IsValid(std::string* error) const;
};

/// For every pixel of a camera's (distorted) image, where its ray lands in the source views.
struct LensMap {
  enum class Kind { kIdentity, kPinhole, kCube };
  Kind kind = Kind::kIdentity;
  /// kIdentity, kPinhole: one view. kCube: the faces used, each square, all the same size.
  std::vector<SourceView> views;
  int width = 0;   ///< the camera image's width
  int height = 0;  ///< and height
  /// Row-major, 3 floats per pixel of the camera image: (x, y, view) with (x, y) the source
  /// pixel (pixel centres at integers) in views[view]. view = -1 (and x = y = 0) where the
  /// pixel has no ray: the undistortion does not converge there, or (radtan, pinhole) the ray
  /// points backwards. Such pixels render as black, background id, no depth.
  std::vector<float> map;
  /// Largest angle between a valid pixel's ray and the optical axis, radians (half the field
  /// of view along the widest direction; beyond pi/2 for lenses that see behind them).
  double max_angle = 0.0;
  /// Pixels with no ray.
  int64_t invalid_pixels = 0;
  /// Smallest and largest source pixels per output pixel step over the image (the smaller
  /// and the larger singular value of d(source)/d(pixel), by central differences of the
  /// neighbours' source points, one-sided at the border), for diagnostics and tests. Over the
  /// valid pixels with a valid neighbour in u and in v; 0 when there is none (kIdentity: 1).
  /// min_scale >= 1 unless max_supersampling or max_source_side capped the views.
  double min_scale = 1.0;
  double max_scale = 1.0;

  /// The (x, y, view) triple of pixel (u, v), u in [0, width), v in [0, height).
  Eigen::Vector3f At(int u, int v) const {
    const std::size_t i = 3 * (static_cast<std::size_t>(v) * width + u);
    return {map[i], map[i + 1], map[i + 2]};
  }
};

/// Builds the source views and the per-pixel map of a camera. Deterministic; costs one
/// CameraModel::Unproject per pixel (about 0.33 s for a strongly distorted 1024 x 768 radtan
/// camera, 0.23 s for a 1280 x 960 fisheye, on one core; bench/kernels_bench). Throws
/// InvalidArgument, message starting "MakeLensMap: ", on invalid options (naming the option
/// and its value) and when no pixel of the image has a ray. Never throws for size: the cube's
/// faces are capped to max_source_side.
LensMap MakeLensMap(const CameraModel& camera, const LensMapOptions& options = {});

}  // namespace saccade::geometry
