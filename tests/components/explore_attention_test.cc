// Exploration's two-stage attention (components/explore_attention.h): the second stage, a face
// search at full resolution in the best saliency zone only, finds the face of the portrait the
// head looks at, where the scene's truth puts it; without it no candidate is a face.
#include "saccade/components/explore_attention.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>

#include "saccade/components/demo/face_truth.h"
#include "saccade/head/fixation.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components {
namespace {

struct View {
  std::vector<render::Frame> frames;
  vision::StereoDepth depth;
};

// Both eyes fixating p_W, and their dense stereo.
View LookAt(const scene::Scene& scene, const Eigen::Vector3d& p_W) {
  const head::HeadModel& head = scene.robot()->head;
  render::RendererOptions options;
  options.cameras = {"left", "right"};
  std::unique_ptr<render::Renderer> renderer = render::MakeRenderer(scene, options);
  scene::SceneState state = scene.InitialState();
  state.joints = head.State(head::FixationSolver(head).Solve(p_W).joints);
  View view;
  view.frames = renderer->Render(state, 0);
  const Image& l = *view.frames.at(0).color;
  const Image& r = *view.frames.at(1).color;
  view.depth =
      vision::DenseStereo().Compute({&l, vision::CameraModelOf(l), vision::CameraPoseOf(l)},
                                    {&r, vision::CameraModelOf(r), vision::CameraPoseOf(r)});
  return view;
}

// Looking at the far portrait, the best saliency zone holds a face (the middle portrait's),
// found at full resolution: the first candidate, where the truth puts it. Looking at the near
// one, it holds none, and the face in the image is not searched for: the second stage examines
// the best zone only. Without the second stage no candidate is a face.
TEST(ExploreAttention, TheSecondStageFindsFacesInTheBestZoneOnly) {
  const scene::Scene scene =
      scene::Scene::Load(std::string(SACCADE_SOURCE_DIR) + "/scenes/portraits.yaml");
  const head::HeadModel& head = scene.robot()->head;
  std::map<std::string, Eigen::Vector3d> faces_W;
  for (const demo::PictureFace& p : demo::FindPictureFaces(scene)) {
    if (p.has_face) faces_W[p.name] = demo::FaceCentreAt(scene, p, 0.0);
  }
  ASSERT_EQ(faces_W.count("astronaut_far"), 1u);
  ASSERT_EQ(faces_W.count("astronaut_near"), 1u);
  const auto none = [](const Eigen::Vector3d&) { return 0.0; };
  const std::vector<Eigen::Vector3d> grid = ReachGrid(head, EyeFieldOfView(head), 2.0);
  ExploreAttention::Options two_stage;
  two_stage.second_stage_faces = true;
  ExploreAttention::Options one_stage;
  const auto count_faces = [](const std::vector<ExploreCandidate>& ranked) {
    return std::count_if(ranked.begin(), ranked.end(), [](const ExploreCandidate& c) {
      return c.source == ExploreCandidate::Source::kFace;
    });
  };

  const View far = LookAt(scene, faces_W.at("astronaut_far"));
  const std::vector<ExploreCandidate> ranked =
      ExploreAttention(head, grid, two_stage).Rank(&far.depth, far.frames[0].color.get(), none);
  ASSERT_FALSE(ranked.empty());
  EXPECT_EQ(ranked.front().source, ExploreCandidate::Source::kFace);
  // Its point, from the box centre and the stereo depth there, at a true face centre (the
  // middle portrait's, which the best zone holds: 4 mm off).
  double nearest = 1e9;
  for (const auto& [name, p_W] : faces_W) {
    nearest = std::min(nearest, (ranked.front().p_W - p_W).norm());
  }
  EXPECT_LT(nearest, 0.03) << ranked.front().p_W.transpose();
  EXPECT_EQ(count_faces(ExploreAttention(head, grid, one_stage)
                            .Rank(&far.depth, far.frames[0].color.get(), none)),
            0);

  const View near = LookAt(scene, faces_W.at("astronaut_near"));
  ASSERT_FALSE(vision::FaceDetector().Detect(*near.frames[0].color).empty());
  EXPECT_EQ(count_faces(ExploreAttention(head, grid, two_stage)
                            .Rank(&near.depth, near.frames[0].color.get(), none)),
            0);
}

// Novelty: a fixated direction's field of view is no longer novel; the opposite one still is.
TEST(ExploreAttention, LookingAtAPlaceTakesItsNoveltyAway) {
  const scene::Scene scene =
      scene::Scene::Load(std::string(SACCADE_SOURCE_DIR) + "/scenes/explore_wall.yaml");
  const head::HeadModel& head = scene.robot()->head;
  ExploreAttention attention(head, {}, ExploreAttention::Options{});
  const Eigen::Vector3d ahead = head.X_WB() * Eigen::Vector3d(2, 0, 0);
  const Eigen::Vector3d left = head.X_WB() * Eigen::Vector3d(0, 2, 0);
  EXPECT_DOUBLE_EQ(attention.Novelty(ahead), 1.0);
  attention.Looked(ahead);
  EXPECT_DOUBLE_EQ(attention.Novelty(ahead), 0.0);
  EXPECT_DOUBLE_EQ(attention.Novelty(left), 1.0);
}

}  // namespace
}  // namespace saccade::components
