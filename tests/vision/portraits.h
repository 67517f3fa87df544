#pragma once
// Test support: scenes/astronaut_and_cat.yaml rendered by the eye cameras with the head fixating a
// chosen world point (head IK), and the ground truth the vision tests compare with.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/geometry/pose.h"
#include "saccade/head/kinematics.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"
#include "saccade/vision/face_detector.h"

namespace saccade::vision::testing {

/// The loaded scene (once per test program).
inline const scene::Scene& Portraits() {
  static const scene::Scene scene =
      scene::Scene::Load(std::string(SACCADE_SOURCE_DIR) + "/scenes/astronaut_and_cat.yaml");
  return scene;
}

inline const scene::Object& FindObject(const std::string& name) {
  for (const scene::Object& object : Portraits().objects()) {
    if (object.name == name) return object;
  }
  throw std::runtime_error("no object " + name);
}

/// One stereo pair with each camera's ground-truth objects.
struct StereoFrame {
  Image left;
  Image right;
  std::vector<render::ObjectTruth> left_truth;
  std::vector<render::ObjectTruth> right_truth;
  head::JointState joints;
};

inline const render::ObjectTruth* FindTruth(const std::vector<render::ObjectTruth>& truth,
                                            const std::string& name) {
  for (const render::ObjectTruth& t : truth) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

/// Renders left and right at `state` (noise and lens as the scene says, truth boxes on).
inline StereoFrame RenderState(const scene::SceneState& state, int64_t frame_index) {
  static const std::unique_ptr<render::Renderer> renderer = [] {
    render::RendererOptions options;
    options.cameras = {"left", "right"};
    options.truth_objects = true;
    return render::MakeRenderer(Portraits(), options);
  }();
  std::vector<render::Frame> frames = renderer->Render(state, frame_index);
  StereoFrame out;
  out.left = *frames.at(0).color;
  out.right = *frames.at(1).color;
  out.left_truth = frames.at(0).objects;
  out.right_truth = frames.at(1).objects;
  out.joints = state.joints;
  return out;
}

/// Renders with the head fixating p_W (symmetric vergence IK); the IK must succeed.
inline StereoFrame RenderFixating(const Eigen::Vector3d& p_W, double time = 0.0,
                                  int64_t frame_index = 0) {
  const head::HeadModel& head = Portraits().robot()->head;
  const head::IkResult ik = head::SolveFixation(*head.AppendixAHead(), p_W);
  EXPECT_TRUE(ik.reachable()) << ik.message;
  scene::SceneState state = Portraits().InitialState();
  state.time = time;
  state.joints = head.State(ik.joints);
  return RenderState(state, frame_index);
}

/// World point of texel (col, row) (centres at integers) of a picture object at time t.
inline Eigen::Vector3d PictureTexelToWorld(const std::string& name, double col, double row,
                                           double t = 0.0) {
  const scene::Object& object = FindObject(name);
  const scene::Model& model = *object.model;
  const Image& texture = model.materials.at(0).texture->image;
  const Eigen::Vector3f lo = model.bounds.min(), hi = model.bounds.max();
  const double y = lo.y() + (col + 0.5) / texture.width() * (hi.y() - lo.y());
  const double z = hi.z() - (row + 0.5) / texture.height() * (hi.z() - lo.z());
  const Eigen::Vector3d p_O(0.0, y * object.scale.y(), z * object.scale.z());
  scene::SceneState state = Portraits().InitialState();
  state.time = t;
  return Portraits().ObjectPose(object, state) * p_O;
}

/// The face box in a picture's own texture, found by the face cascade on the texture itself
/// (the largest; the texture is the ground truth of what the picture shows).
inline cv::Rect FaceBoxInTexture(const std::string& name) {
  const Image& texture = FindObject(name).model->materials.at(0).texture->image;
  Image rgb = texture;
  FaceDetector::Options options;
  options.cat_cascade_path = "";
  FaceDetector detector(options);
  const std::vector<FaceDetection> faces = detector.Detect(rgb);
  EXPECT_FALSE(faces.empty()) << "no face in the texture of " << name;
  return faces.empty() ? cv::Rect() : faces.front().box;
}

/// World position of the centre of the face box in a picture's texture.
inline Eigen::Vector3d FaceCentreWorld(const std::string& name, double t = 0.0) {
  const cv::Rect box = FaceBoxInTexture(name);
  return PictureTexelToWorld(name, box.x + (box.width - 1) / 2.0, box.y + (box.height - 1) / 2.0,
                             t);
}

}  // namespace saccade::vision::testing
