#include "saccade/components/demo/face_truth.h"

#include <algorithm>
#include <array>

#include "saccade/vision/face_detector.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components::demo {

std::vector<PictureFace> FindPictureFaces(const scene::Scene& scene) {
  std::vector<PictureFace> out;
  vision::FaceDetector detector;
  const auto& objects = scene.objects();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const scene::Object& object = objects[i];
    const scene::Model& model = *object.model;
    if (model.source.rfind("picture:", 0) != 0 || model.materials.empty() ||
        !model.materials[0].texture) {
      continue;
    }
    PictureFace face;
    face.name = object.name;
    face.object = i;
    const Image& texture = model.materials[0].texture->image;
    for (const vision::FaceDetection& d : detector.Detect(texture)) {
      if (d.rejected) continue;
      // The picture spans the model bounds in y (columns) and z (rows, top at max z):
      // scene.h's MakePicture.
      const Eigen::Vector3f lo = model.bounds.min(), hi = model.bounds.max();
      const cv::Point2d c = d.Center();
      const double y = lo.y() + (c.x + 0.5) / texture.width() * (hi.y() - lo.y());
      const double z = hi.z() - (c.y + 0.5) / texture.height() * (hi.z() - lo.z());
      face.p_O = Eigen::Vector3d(0.0, y * object.scale.y(), z * object.scale.z());
      face.width_m = d.box.width * (hi.y() - lo.y()) * object.scale.y() / texture.width();
      face.has_face = true;
      break;  // the largest accepted box
    }
    out.push_back(face);
  }
  return out;
}

Eigen::Vector3d FaceCentreAt(const scene::Scene& scene, const PictureFace& face, double t) {
  scene::SceneState state = scene.InitialState();
  state.time = t;
  return scene.ObjectPose(scene.objects().at(face.object), state) * face.p_O;
}

std::optional<std::array<double, 4>> ProjectedBox(const scene::Scene& scene,
                                                  const scene::Object& object, const Image& image) {
  const geometry::CameraModel camera = vision::CameraModelOf(image);
  const geometry::Pose X_CW = vision::CameraPoseOf(image).inverse();
  scene::SceneState state = scene.InitialState();
  state.time = image.metadata().time;
  const geometry::Pose X_WO = scene.ObjectPose(object, state);
  const Eigen::Vector3f lo = object.model->bounds.min(), hi = object.model->bounds.max();
  std::array<double, 4> box = {1e300, 1e300, -1e300, -1e300};
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p_O((corner & 1 ? hi : lo).x() * object.scale.x(),
                              (corner & 2 ? hi : lo).y() * object.scale.y(),
                              (corner & 4 ? hi : lo).z() * object.scale.z());
    const Eigen::Vector3d p_C = X_CW * (X_WO * p_O);
    if (p_C.z() <= 0.0) return std::nullopt;
    const std::optional<Eigen::Vector2d> uv = camera.Project(p_C);
    if (!uv) return std::nullopt;
    box = {std::min(box[0], uv->x()), std::min(box[1], uv->y()), std::max(box[2], uv->x()),
           std::max(box[3], uv->y())};
  }
  if (box[2] < 0 || box[3] < 0 || box[0] > image.width() - 1 || box[1] > image.height() - 1) {
    return std::nullopt;
  }
  return box;
}

}  // namespace saccade::components::demo
