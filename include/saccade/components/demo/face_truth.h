#pragma once
// Ground truth for the active-vision loop: where the faces of a scene's pictures are, and
// where objects appear in an image. The demo and the closed-loop tests measure fixation
// accuracy against it. A picture's face is what the face detector (default options, cat and
// eye checks on) finds in the picture's own texture, the largest accepted box: its centre,
// placed on the picture in the world, is the "true face centre". Pictures in which it finds
// none (the cat) are decoys.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/scene/scene.h"

namespace saccade::components::demo {

struct PictureFace {
  std::string name;        ///< the object's name
  std::size_t object = 0;  ///< index into scene.objects()
  bool has_face = false;   ///< false: a decoy (no accepted face in its texture)
  Eigen::Vector3d p_O = Eigen::Vector3d::Zero();  ///< face centre in the object frame, m
  double width_m = 0.0;                           ///< the face box's width on the picture, m
};

/// Every picture of the scene, in scene order. Runs the face detector on each texture once.
std::vector<PictureFace> FindPictureFaces(const scene::Scene& scene);

/// The face centre in the world at time t (s).
Eigen::Vector3d FaceCentreAt(const scene::Scene& scene, const PictureFace& face, double t);

/// The box (pixels, inclusive) of an object's model bounds projected into `image` (its
/// metadata's camera and X_WC) at the image's time; std::nullopt when a corner is behind the
/// camera or the box misses the image.
std::optional<std::array<double, 4>> ProjectedBox(const scene::Scene& scene,
                                                  const scene::Object& object, const Image& image);

}  // namespace saccade::components::demo
