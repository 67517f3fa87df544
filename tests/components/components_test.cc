// Each component of the loop on its own: the perception components on rendered images of the
// two-picture scene, attention, fixation and the motors on known inputs, and their errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <thread>

#include "image_camera_helpers.h"
#include "saccade/components/demo/face_truth.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/head/kinematics.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "saccade/vision/image_camera.h"
#include "saccade/vision/median_filter.h"
#include "saccade/vision/sharpener.h"
#include "saccade/vision/undistorter.h"

namespace saccade::components {
namespace {

using demo::FaceCentreAt;
using demo::FindPictureFaces;
using demo::PictureFace;
using nlohmann::json;
using runtime::Component;

const std::string kScene = std::string(SACCADE_SOURCE_DIR) + "/scenes/astronaut_and_cat.yaml";

// Triangulated detections of a ~100 px face at 2.2 m: the box centres differ between the eyes
// by a pixel or two (quantisation), i.e. a few centimetres in depth at this baseline.
constexpr double kTriangulationToleranceM = 0.03;
// IK solutions are exact to ~1e-9 rad (kinematics.h); FK of them back to the point.
constexpr double kIkToleranceM = 1e-6;

/// The resources every component of this test program shares, as a pipeline's components do:
/// the scene is loaded once.
std::shared_ptr<runtime::Resources> SharedResources() {
  RegisterComponents();
  static const std::shared_ptr<runtime::Resources> resources =
      std::make_shared<runtime::Resources>(runtime::ComponentRegistry::Global().resource_loaders());
  return resources;
}

/// The scene, as the components see it.
const scene::Scene& Scene() {
  static const std::shared_ptr<const scene::Scene> scene =
      SharedResources()->Load<scene::Scene>("scene", kScene);
  return *scene;
}

std::unique_ptr<Component> Make(const std::string& type, const json& params) {
  RegisterComponents();
  std::unique_ptr<Component> c = runtime::ComponentRegistry::Global().Create(type);
  c->Initialise(type, 1, {}, SharedResources());
  c->Configure(params);
  return c;
}

template <typename T>
runtime::Input<T>& In(Component& c, const std::string& name) {
  auto* input = dynamic_cast<runtime::Input<T>*>(c.FindInput(name));
  EXPECT_NE(input, nullptr) << name;
  return *input;
}

/// The latest message an output sent.
template <typename T>
std::shared_ptr<std::optional<T>> Capture(Component& c, const std::string& name) {
  auto latest = std::make_shared<std::optional<T>>();
  auto* output = dynamic_cast<runtime::Output<T>*>(c.FindOutput(name));
  EXPECT_NE(output, nullptr) << name;
  output->signal().Connect([latest](const T& m) { *latest = m; });
  return latest;
}

runtime::StepContext At(int64_t step) {
  runtime::StepContext context;
  context.step = step;
  context.dt = 0.04;
  context.time = step * context.dt;
  return context;
}

PictureFace Astronaut() {
  for (const PictureFace& p : FindPictureFaces(Scene())) {
    if (p.has_face) return p;
  }
  ADD_FAILURE() << "no face in " << kScene;
  return {};
}

// The head fixates a point beside the face: the face is detected in both eyes, the cat's
// candidates rejected, the pair triangulated onto the true face centre, selected, tracked,
// and the fixation command turns the head onto it.
TEST(PerceptionComponents, FromRenderedImagesToACommandThatFixatesTheFace) {
  const scene::Scene& scene = Scene();
  const Eigen::Vector3d face = FaceCentreAt(scene, Astronaut(), 0.0);
  const head::IkResult look = head::SolveFixation(*scene.robot()->head.AppendixAHead(),
                                                  face + Eigen::Vector3d(0, 0.1, -0.05));
  ASSERT_TRUE(look.reachable());

  auto cameras = Make("sim.cameras", {{"scene", kScene}});
  auto faces_left = Make("vision.face_detector", json::object());
  auto faces_right = Make("vision.face_detector", json::object());
  auto stereo = Make("vision.stereo_faces", json::object());
  auto attention = Make("vision.attention", {{"scene", kScene}});
  auto track_left = Make("vision.camshift", {{"eye", "left"}});
  auto track_right = Make("vision.camshift", {{"eye", "right"}});
  auto triangulate = Make("vision.triangulate", json::object());
  auto fixation = Make("control.fixation", {{"scene", kScene}});
  auto left = Capture<runtime::ImageMessage>(*cameras, "left");
  auto right = Capture<runtime::ImageMessage>(*cameras, "right");
  auto fl = Capture<FacesMessage>(*faces_left, "faces");
  auto fr = Capture<FacesMessage>(*faces_right, "faces");
  auto candidates = Capture<CandidatesMessage>(*stereo, "candidates");
  auto selection = Capture<SelectionMessage>(*attention, "selection");
  auto tl = Capture<TrackMessage>(*track_left, "track");
  auto tr = Capture<TrackMessage>(*track_right, "track");
  auto target = Capture<TargetMessage>(*triangulate, "target");
  auto command = Capture<JointCommand>(*fixation, "command");

  cameras->Start();
  for (int64_t step = 0; step < 3; ++step) {
    JointStateMessage joints;
    joints.positions = joints.velocities = joints.targets = joints.target_velocities =
        head::JointState::Popeye(0, 0, 0, 0);
    joints.time = At(step).time;
    joints.positions = look.joints;
    In<JointStateMessage>(*cameras, "joints").Deliver(joints);
    cameras->Step(At(step));
    ASSERT_TRUE(*left && *right);
    EXPECT_EQ((*left)->image->metadata().frame_index, step);
    EXPECT_EQ((*left)->image->metadata().joints[0], look.joints[0]);  // rendered at the joints
    In<runtime::ImageMessage>(*faces_left, "image").Deliver(**left);
    In<runtime::ImageMessage>(*faces_right, "image").Deliver(**right);
    faces_left->Step(At(step));
    faces_right->Step(At(step));
    for (auto* in : {&faces_left, &faces_right}) (*in)->inputs()[0]->MarkSeen();
    In<FacesMessage>(*stereo, "left").Deliver(**fl);
    In<FacesMessage>(*stereo, "right").Deliver(**fr);
    stereo->Step(At(step));
    In<CandidatesMessage>(*attention, "candidates").Deliver(**candidates);
    attention->Step(At(step));
    for (auto* t : {&track_left, &track_right}) {
      In<runtime::ImageMessage>(**t, "image").Deliver(t == &track_left ? **left : **right);
      In<SelectionMessage>(**t, "selection").Deliver(**selection);
      (*t)->Step(At(step));
    }
    In<TrackMessage>(*triangulate, "left").Deliver(**tl);
    In<TrackMessage>(*triangulate, "right").Deliver(**tr);
    In<SelectionMessage>(*triangulate, "selection").Deliver(**selection);
    triangulate->Step(At(step));
    In<TargetMessage>(*fixation, "target").Deliver(**target);
    fixation->Step(At(step));
  }
  cameras->Stop();

  // One accepted face per eye; whatever fired on the cat is flagged, never accepted.
  for (const auto* faces : {&*fl, &*fr}) {
    int accepted = 0;
    for (const FacesMessage::Face& f : (*faces)->faces) accepted += f.rejected ? 0 : 1;
    EXPECT_EQ(accepted, 1);
  }
  ASSERT_EQ((*candidates)->candidates.size(), 1u);
  EXPECT_LT(((*candidates)->candidates[0].p_W - face).norm(), kTriangulationToleranceM);
  ASSERT_TRUE((*selection)->valid);
  EXPECT_EQ((*selection)->target_id, 0);  // the same target over the three frames
  EXPECT_FALSE((*selection)->fixating);   // no joints: the head is not known to be on it
  EXPECT_TRUE((*tl)->tracking);
  EXPECT_TRUE((*tr)->tracking);
  EXPECT_TRUE((*tl)->window.contains(cv::Point((*tl)->center)));
  ASSERT_TRUE((*target)->valid);
  EXPECT_LT(((*target)->p_W - face).norm(), kTriangulationToleranceM);
  // The command fixates the target exactly: both optical axes meet on it.
  const head::HeadFrames frames = head::ForwardKinematics(
      *scene.robot()->head.AppendixAHead(), head::PopeyeJoints::From((*command)->positions));
  ASSERT_TRUE(frames.p_WFixation);
  EXPECT_LT((*frames.p_WFixation - (*target)->p_W).norm(), kIkToleranceM);
  EXPECT_FALSE((*command)->pursuit());  // a still face: a saccade
}

/// One frame of `camera` from sim.cameras on `scene_file` with the head at rest at `joints`
/// moving at `velocities`.
std::shared_ptr<const Image> RenderOne(const std::string& scene_file, const std::string& camera,
                                       const head::JointState& joints,
                                       const head::JointState& velocities) {
  auto cameras = Make("sim.cameras", {{"scene", scene_file}, {"cameras", {camera}}});
  auto image = Capture<runtime::ImageMessage>(*cameras, camera);
  cameras->Start();
  JointStateMessage state;
  state.positions = state.velocities = state.targets = state.target_velocities =
      head::JointState::Popeye(0, 0, 0, 0);
  state.positions = joints;
  state.velocities = velocities;
  In<JointStateMessage>(*cameras, "joints").Deliver(state);
  cameras->Step(At(0));
  cameras->Stop();
  return (*image)->image;
}

double Sharpness(const Image& image) {
  cv::Mat rgb(image.height(), image.width(), CV_8UC3, const_cast<uint8_t*>(image.data()));
  cv::Mat gray, laplacian;
  cv::cvtColor(rgb, gray, cv::COLOR_RGB2GRAY);
  cv::Laplacian(gray, laplacian, CV_64F);
  cv::Scalar mean, stddev;
  cv::meanStdDev(laplacian, mean, stddev);
  return stddev[0] * stddev[0];
}

// The motors' velocities reach the renderer: a saccade in progress blurs the eye's image
// (scenes/portraits.yaml's eye cameras expose for 8 ms).
// Pipelined capture: each step submits its state and emits the previous step's frames,
// exactly those an unpipelined camera renders for that step (frame index, joints, pixels).
TEST(SimCameras, PipelinedCaptureEmitsThePreviousStepsFrameUnchanged) {
  auto pipelined =
      Make("sim.cameras", {{"scene", kScene}, {"cameras", {"left"}}, {"pipelined", "always"}});
  auto plain =
      Make("sim.cameras", {{"scene", kScene}, {"cameras", {"left"}}, {"pipelined", "never"}});
  auto got = Capture<runtime::ImageMessage>(*pipelined, "left");
  auto want = Capture<runtime::ImageMessage>(*plain, "left");
  pipelined->Start();
  plain->Start();
  std::shared_ptr<const Image> previous;
  for (int64_t step = 0; step < 4; ++step) {
    JointStateMessage joints;
    joints.positions = joints.velocities = joints.targets = joints.target_velocities =
        head::JointState::Popeye(0, 0, 0, 0);
    joints.time = At(step).time;
    joints.positions = head::JointState::Popeye(0.05 * step, -0.02 * step, 0.0, 0.0);
    In<JointStateMessage>(*pipelined, "joints").Deliver(joints);
    In<JointStateMessage>(*plain, "joints").Deliver(joints);
    pipelined->Step(At(step));
    plain->Step(At(step));
    if (step == 0) {
      EXPECT_FALSE(got->has_value());  // nothing rendered before the first step
    } else {
      ASSERT_TRUE(got->has_value());
      const Image& image = *(*got)->image;
      EXPECT_EQ(image.metadata().frame_index, step - 1);
      EXPECT_DOUBLE_EQ(image.metadata().time, At(step - 1).time);
      EXPECT_DOUBLE_EQ(image.metadata().joints[0], 0.05 * (step - 1));
      ASSERT_EQ(image.size_bytes(), previous->size_bytes());
      EXPECT_EQ(std::memcmp(image.data(), previous->data(), image.size_bytes()), 0) << step;
    }
    previous = (*want)->image;
  }
  pipelined->Stop();
  plain->Stop();
}

// The renderer draws on a thread of its own: while a step waits for its frames it calls
// StepContext::while_waiting, on the step's thread (where a GUI applies its commands).
TEST(SimCameras, WhileWaitingRunsOnTheStepsThreadWhileTheRendererDraws) {
  for (const char* mode : {"never", "always"}) {
    auto cameras =
        Make("sim.cameras", {{"scene", kScene}, {"cameras", {"left"}}, {"pipelined", mode}});
    auto got = Capture<runtime::ImageMessage>(*cameras, "left");
    cameras->Start();
    std::vector<std::thread::id> calls;
    const std::function<void()> hook = [&] { calls.push_back(std::this_thread::get_id()); };
    const bool pipelined = std::string(mode) == "always";
    for (int64_t step = 0; step < 4; ++step) {
      runtime::StepContext context = At(step);
      context.while_waiting = &hook;
      const std::size_t before = calls.size();
      cameras->Step(context);
      if (pipelined && step == 0) {
        EXPECT_FALSE(got->has_value());
        EXPECT_EQ(calls.size(), before);  // nothing to wait for: the render goes on alone
        continue;
      }
      ASSERT_TRUE(got->has_value()) << mode;
      EXPECT_EQ((*got)->image->metadata().frame_index, pipelined ? step - 1 : step) << mode;
      if (!pipelined) {
        EXPECT_GT(calls.size(), before) << step;  // it waited for a whole render
      }
    }
    cameras->Stop();
    for (const std::thread::id& id : calls) EXPECT_EQ(id, std::this_thread::get_id()) << mode;
  }
}

// The left eye's image with the head fixating the astronaut's face; null when it cannot.
std::shared_ptr<const Image> LeftEyeOnTheAstronaut() {
  const scene::Scene& scene = Scene();
  const head::IkResult look = head::SolveFixation(*scene.robot()->head.AppendixAHead(),
                                                  FaceCentreAt(scene, Astronaut(), 0.0));
  EXPECT_TRUE(look.reachable());
  if (!look.reachable()) return nullptr;
  return RenderOne(kScene, "left", look.joints, {});
}

// The faces a detector (default parameters, or `params`) finds in the whole image.
FacesMessage DetectWhole(const std::shared_ptr<const Image>& image,
                         const json& params = json::object()) {
  auto detector = Make("vision.face_detector", params);
  auto faces = Capture<FacesMessage>(*detector, "faces");
  In<runtime::ImageMessage>(*detector, "image").Deliver(runtime::ImageMessage{image});
  detector->Step(At(0));
  EXPECT_TRUE(faces->has_value());
  return faces->value_or(FacesMessage{});
}

// Each face's box and verdict, to compare two searches.
std::vector<std::array<int, 5>> Boxes(const FacesMessage& faces) {
  std::vector<std::array<int, 5>> out;
  for (const FacesMessage::Face& f : faces.faces) {
    out.push_back({f.box.x, f.box.y, f.box.width, f.box.height, f.rejected ? 1 : 0});
  }
  return out;
}

// A track on the sky, top left of an eye on the astronaut: the search around it finds nothing.
TrackMessage TrackOnTheSky() {
  TrackMessage track;
  track.tracking = true;
  track.window = cv::Rect(20, 20, 80, 80);
  track.center = {60.0, 60.0};
  return track;
}

// The box of the last face not rejected, if any.
std::optional<cv::Rect> AcceptedBox(const FacesMessage& faces) {
  std::optional<cv::Rect> box;
  for (const FacesMessage::Face& f : faces.faces) {
    if (!f.rejected) box = f.box;
  }
  return box;
}

// Detect slowly, track fast: with a track, the detector searches a box around it, and the
// whole image every full_scan_every-th time.
TEST(FaceDetectorComponent, SearchesAroundTheTrackAndTheWholeImageEveryNthTime) {
  const std::shared_ptr<const Image> image = LeftEyeOnTheAstronaut();
  ASSERT_TRUE(image);
  const FacesMessage whole = DetectWhole(image);
  const std::optional<cv::Rect> face = AcceptedBox(whole);
  ASSERT_TRUE(face);
  const std::size_t candidates = whole.faces.size();

  auto around =
      Make("vision.face_detector",
           {{"track_region_scale", 2.0}, {"full_scan_every", 2}, {"new_target_scans", 0}});
  auto faces = Capture<FacesMessage>(*around, "faces");
  const auto detect = [&](const cv::Rect& window, int64_t step) {
    TrackMessage track;
    track.tracking = true;
    track.window = window;
    track.center = {window.x + 0.5 * window.width, window.y + 0.5 * window.height};
    In<TrackMessage>(*around, "track").Deliver(track);
    In<runtime::ImageMessage>(*around, "image").Deliver(runtime::ImageMessage{image});
    around->Step(At(step));
    return (*faces)->faces;
  };
  const cv::Rect elsewhere(20, 20, face->width, face->height);    // the sky, top left
  EXPECT_EQ(detect(elsewhere, 0).size(), candidates);             // 1st: the whole image
  EXPECT_TRUE(detect(elsewhere, 1).empty());                      // 2nd: around the track
  EXPECT_EQ(detect(elsewhere, 2).size(), candidates);             // 3rd: the whole image
  const std::vector<FacesMessage::Face> near = detect(*face, 3);  // 4th: around the face
  ASSERT_EQ(near.size(), 1u);
  EXPECT_FALSE(near[0].rejected);
  // The same cascade on the same pixels: the same face. The box is the mean of the cascade's
  // overlapping hits, some of which the region's edge cuts off: a few pixels on ~90.
  const double kBoxTolerancePx = 0.05 * face->width;
  EXPECT_NEAR(near[0].box.x + 0.5 * near[0].box.width, face->x + 0.5 * face->width,
              kBoxTolerancePx);
  EXPECT_NEAR(near[0].box.y + 0.5 * near[0].box.height, face->y + 0.5 * face->height,
              kBoxTolerancePx);
  EXPECT_NEAR(near[0].box.width, face->width, kBoxTolerancePx);
}

// With a track, the whole-image searches look for the other faces, at discovery_scale_factor
// (the tracked face's box comes from the search around it, at scale_factor): their faces are
// those of a detector searching the whole image at that step.
TEST(FaceDetectorComponent, WithATrackSearchesTheWholeImageAtTheDiscoveryStep) {
  const std::shared_ptr<const Image> image = LeftEyeOnTheAstronaut();
  ASSERT_TRUE(image);
  const auto fine = Boxes(DetectWhole(image));  // scale_factor 1.1
  const auto coarse = Boxes(DetectWhole(image, {{"scale_factor", 1.3}}));
  ASSERT_FALSE(coarse.empty());
  ASSERT_NE(fine, coarse);  // else this test could not tell them apart

  auto detector = Make("vision.face_detector", {{"track_region_scale", 2.0},
                                                {"full_scan_every", 1},
                                                {"new_target_scans", 0},
                                                {"discovery_scale_factor", 1.3}});
  auto faces = Capture<FacesMessage>(*detector, "faces");
  const auto detect = [&](bool with_track, int64_t step) {
    if (with_track) {
      In<TrackMessage>(*detector, "track").Deliver(TrackOnTheSky());
    }
    In<runtime::ImageMessage>(*detector, "image").Deliver(runtime::ImageMessage{image});
    detector->Step(At(step));
    return Boxes(**faces);
  };
  EXPECT_EQ(detect(false, 0), fine);  // no track yet: the whole image at scale_factor
  EXPECT_EQ(detect(true, 1), coarse);
  EXPECT_EQ(detect(true, 2), coarse);
}

// A face that one eye alone sees cannot be triangulated: with the other eye's faces of the
// same capture (the partner input), the detector searches their epipolar bands instead of the
// whole image, and finds there what the whole image holds of them.
TEST(FaceDetectorComponent, WithThePartnersFacesSearchesTheirEpipolarBandsNotTheWholeImage) {
  // The eyes verge on a point 5 m beyond her, so that her face lies well apart in the two
  // images (crossed disparity): a band in the wrong place would miss it.
  const scene::Scene& scene = Scene();
  const Eigen::Vector3d her_W = FaceCentreAt(scene, Astronaut(), 0.0);
  const Eigen::Vector3d base_W =
      head::ForwardKinematics(*scene.robot()->head.AppendixAHead(),
                              head::PopeyeJoints::From(scene.robot()->initial_joints))
          .X_WC.translation();
  const head::IkResult look = head::SolveFixation(*scene.robot()->head.AppendixAHead(),
                                                  her_W + 5.0 * (her_W - base_W).normalized());
  ASSERT_TRUE(look.reachable());
  const std::shared_ptr<const Image> left = RenderOne(kScene, "left", look.joints, {});
  const std::shared_ptr<const Image> right = RenderOne(kScene, "right", look.joints, {});
  ASSERT_EQ(left->metadata().time, right->metadata().time);
  const FacesMessage partner = DetectWhole(left);
  const std::optional<cv::Rect> her_left = AcceptedBox(partner);
  const std::optional<cv::Rect> her = AcceptedBox(DetectWhole(right));
  ASSERT_TRUE(her_left);
  ASSERT_TRUE(her);

  auto detector = Make("vision.face_detector", json::object());
  auto faces = Capture<FacesMessage>(*detector, "faces");
  int64_t step = 0;
  const auto detect = [&](const FacesMessage& other) {
    In<FacesMessage>(*detector, "partner").Deliver(other);
    In<runtime::ImageMessage>(*detector, "image").Deliver(runtime::ImageMessage{right});
    detector->Step(At(step++));
    return AcceptedBox(**faces);
  };
  const std::optional<cv::Rect> found = detect(partner);
  ASSERT_TRUE(found);
  EXPECT_LT(cv::norm((found->tl() + found->br()) - (her->tl() + her->br())) / 2.0,
            0.05 * her->width);
  EXPECT_NEAR(found->width, her->width, 0.05 * her->width);
  // The left eye saw nothing: nothing is searched for, where the whole image would find her.
  FacesMessage none = partner;
  none.faces.clear();
  EXPECT_FALSE(detect(none));
  // Faces of another capture say nothing of this one: the whole image.
  auto later = std::make_shared<Image>(*left);
  later->metadata().time += 0.04;
  none.image = later;
  EXPECT_TRUE(detect(none));
}

// A new target (the track's target_id changes, as when attention moves on and the eyes make
// a saccade): its first new_target_scans detections search the whole image as well, so that a
// tracker the saccade carried onto another face is corrected by the next pairing.
TEST(FaceDetectorComponent, SearchesTheWholeImageOnTheFirstDetectionsOfANewTarget) {
  const std::shared_ptr<const Image> image = LeftEyeOnTheAstronaut();
  ASSERT_TRUE(image);
  auto around =
      Make("vision.face_detector",
           {{"track_region_scale", 2.0}, {"full_scan_every", 1000}, {"new_target_scans", 2}});
  auto faces = Capture<FacesMessage>(*around, "faces");
  int64_t step = 0;
  // How many faces a detection found with the track on the sky, far from every face: none
  // around it, all of them when the whole image is searched too.
  const auto detect = [&](int64_t target_id) {
    TrackMessage track;
    track.tracking = true;
    track.target_id = target_id;
    track.window = cv::Rect(20, 20, 80, 80);
    track.center = {60.0, 60.0};
    In<TrackMessage>(*around, "track").Deliver(track);
    In<runtime::ImageMessage>(*around, "image").Deliver(runtime::ImageMessage{image});
    around->Step(At(step++));
    return (*faces)->faces.size();
  };
  EXPECT_GT(detect(0), 0u);  // target 0: the whole image (also the 1st of full_scan_every)
  EXPECT_GT(detect(0), 0u);  //   and its 2nd detection
  EXPECT_EQ(detect(0), 0u);  //   then around its track only
  EXPECT_EQ(detect(0), 0u);
  EXPECT_GT(detect(1), 0u);  // target 1: the whole image twice again
  EXPECT_GT(detect(1), 0u);
  EXPECT_EQ(detect(1), 0u);
}

// With attention's selection connected, a new target's first detections search around where
// its 3D point projects in the image, not the whole image: the astronaut is found where the
// selection puts her, nothing where it puts a point of the sky (the whole image would have
// found her), and without a selection of that target the whole image is searched again.
TEST(FaceDetectorComponent, SearchesANewTargetWhereTheSelectionPutsIt) {
  const std::shared_ptr<const Image> image = LeftEyeOnTheAstronaut();
  ASSERT_TRUE(image);
  const std::optional<cv::Rect> face = AcceptedBox(DetectWhole(image));
  ASSERT_TRUE(face);
  const Eigen::Vector3d her = FaceCentreAt(Scene(), Astronaut(), 0.0);
  // A point of the sky, up and left of her in this image, out of reach of a box around her.
  const geometry::Pose X_WC = vision::CameraPoseOf(*image);
  const Eigen::Vector3d sky = X_WC * Eigen::Vector3d(-0.5, -0.4, 2.5);
  const std::optional<Eigen::Vector2d> sky_px =
      vision::CameraModelOf(*image).Project(X_WC.inverse() * sky);
  ASSERT_TRUE(sky_px);
  ASSERT_TRUE(
      cv::Rect(0, 0, image->width(), image->height())
          .contains(cv::Point(static_cast<int>(sky_px->x()), static_cast<int>(sky_px->y()))));
  ASSERT_GT(cv::norm(cv::Point2d(sky_px->x(), sky_px->y()) -
                     cv::Point2d(face->x + 0.5 * face->width, face->y + 0.5 * face->height)),
            3.0 * face->width);

  auto detector =
      Make("vision.face_detector",
           {{"track_region_scale", 2.0}, {"full_scan_every", 1000}, {"new_target_scans", 2}});
  auto faces = Capture<FacesMessage>(*detector, "faces");
  int64_t step = 1;  // not a multiple of full_scan_every's
  const auto detect = [&](int64_t target_id, const std::optional<Eigen::Vector3d>& p_W) {
    TrackMessage track;  // on the sky, far from every face
    track.tracking = true;
    track.target_id = target_id;
    track.window = cv::Rect(20, 20, 80, 80);
    track.center = {60.0, 60.0};
    In<TrackMessage>(*detector, "track").Deliver(track);
    SelectionMessage selection;
    selection.valid = p_W.has_value();
    selection.target_id = target_id;
    selection.p_W = p_W.value_or(Eigen::Vector3d::Zero());
    selection.boxes_fresh = true;
    selection.left_box = selection.right_box = *face;
    In<SelectionMessage>(*detector, "selection").Deliver(selection);
    In<runtime::ImageMessage>(*detector, "image").Deliver(runtime::ImageMessage{image});
    detector->Step(At(step++));
    return AcceptedBox(**faces);
  };
  const std::optional<cv::Rect> found = detect(0, her);  // target 0: her face
  ASSERT_TRUE(found);
  EXPECT_LT(cv::norm((found->tl() + found->br()) - (face->tl() + face->br())) / 2.0,
            0.05 * face->width);
  EXPECT_FALSE(detect(1, sky));  // target 1: the sky; the whole image would find her
  EXPECT_FALSE(detect(1, sky));
  EXPECT_TRUE(detect(2, std::nullopt));  // no selection: the whole image
  EXPECT_TRUE(detect(2, std::nullopt));
  EXPECT_FALSE(detect(2, std::nullopt));  // then around the track only
}

// A new target keeps the verdict that made it a target (attention chooses only faces that both
// eyes accepted) while the head turns to it: the face found where the selection puts it takes
// that verdict instead of the cat and eye cascades', and is checked again like any face
// (recheck_every). Shown on a box the cascades reject, as if attention had chosen it.
TEST(FaceDetectorComponent, ANewTargetKeepsItsVerdictUntilItsRecheck) {
  const std::shared_ptr<const Image> image = LeftEyeOnTheAstronaut();
  ASSERT_TRUE(image);
  // Every hit of the face cascade a box (no grouping): boxes on the cat and elsewhere too,
  // which the cat and eye checks reject.
  const json hits = {{"min_neighbors", 0}};
  const geometry::Pose X_WC = vision::CameraPoseOf(*image);
  // Per detection of a new target on `box`: 1 accepted, 0 rejected, -1 not found.
  const auto run = [&](const cv::Rect& box, bool keep) {
    // A point on the box's centre ray (any depth projects there).
    const Eigen::Vector2d centre(box.x + 0.5 * box.width, box.y + 0.5 * box.height);
    const std::optional<Eigen::Vector3d> ray = vision::CameraModelOf(*image).Unproject(centre);
    EXPECT_TRUE(ray);
    const Eigen::Vector3d p_W = X_WC * (ray.value_or(Eigen::Vector3d::UnitZ()) * 2.0);
    json params = hits;
    params.update({{"track_region_scale", 2.0},
                   {"full_scan_every", 1000},
                   {"new_target_scans", 3},
                   {"recheck_every", 4},
                   {"keep_target_verdict", keep}});
    auto detector = Make("vision.face_detector", params);
    auto faces = Capture<FacesMessage>(*detector, "faces");
    std::vector<int> verdicts;
    for (int64_t step = 1; step <= 8; ++step) {  // step 0 would search the whole image
      TrackMessage track;
      track.tracking = true;
      track.target_id = 7;
      track.window = box;
      track.center = {centre.x(), centre.y()};
      In<TrackMessage>(*detector, "track").Deliver(track);
      SelectionMessage selection;
      selection.valid = true;
      selection.target_id = 7;
      selection.p_W = p_W;
      selection.boxes_fresh = true;
      selection.left_box = selection.right_box = box;
      In<SelectionMessage>(*detector, "selection").Deliver(selection);
      In<runtime::ImageMessage>(*detector, "image").Deliver(runtime::ImageMessage{image});
      detector->Step(At(step));
      int verdict = -1;
      for (const FacesMessage::Face& f : (*faces)->faces) {
        if ((f.box & box).area() > 0.5 * box.area()) verdict = f.rejected ? 0 : 1;
      }
      verdicts.push_back(verdict);
    }
    return verdicts;
  };
  // A box the cascades reject on every search around it, as if attention had chosen it.
  const std::vector<int> every_time_rejected(8, 0);
  std::optional<cv::Rect> rejected;
  for (const FacesMessage::Face& f : DetectWhole(image, hits).faces) {
    if (f.rejected && !rejected && run(f.box, false) == every_time_rejected) rejected = f.box;
  }
  ASSERT_TRUE(rejected) << "no box that the searches around it find and reject";
  // Kept: the target's verdict serves recheck_every - 1 = 3 searches, as a face's own verdict
  // does, then the face is checked and rejected.
  EXPECT_EQ(run(*rejected, true), (std::vector<int>{1, 1, 1, 0, 0, 0, 0, 0}));
}

// Around a tracked face the detector searches only sizes near the track window's and, between
// the rechecks, keeps the face's verdict instead of running the cat and eye cascades again
// (FaceDetector's own tests show both): on the same frames it gives the same faces as checking
// every time at every size.
TEST(FaceDetectorComponent, KeepingVerdictsAndBoundingSizesGivesTheSameFaces) {
  const std::shared_ptr<const Image> image = LeftEyeOnTheAstronaut();
  ASSERT_TRUE(image);
  const std::optional<cv::Rect> face = AcceptedBox(DetectWhole(image));
  ASSERT_TRUE(face);
  const auto run = [&](const json& params) {
    auto detector = Make("vision.face_detector", params);
    auto faces = Capture<FacesMessage>(*detector, "faces");
    std::vector<std::vector<FacesMessage::Face>> out;
    for (int64_t step = 0; step < 12; ++step) {
      TrackMessage track;
      track.tracking = true;
      track.target_id = step < 8 ? 0 : 1;  // a new target: whole scans, verdicts forgotten
      track.window = *face + cv::Point(static_cast<int>(step % 3) - 1, 0);
      track.center = {track.window.x + 0.5 * track.window.width,
                      track.window.y + 0.5 * track.window.height};
      In<TrackMessage>(*detector, "track").Deliver(track);
      In<runtime::ImageMessage>(*detector, "image").Deliver(runtime::ImageMessage{image});
      detector->Step(At(step));
      out.push_back((*faces)->faces);
    }
    return out;
  };
  const auto every_time =
      run({{"recheck_every", 1}, {"region_size_factor", 0.0}, {"new_target_scans", 2}});
  const auto kept =
      run({{"recheck_every", 5}, {"region_size_factor", 2.0}, {"new_target_scans", 2}});
  ASSERT_EQ(kept.size(), every_time.size());
  for (std::size_t k = 0; k < kept.size(); ++k) {
    ASSERT_EQ(kept[k].size(), every_time[k].size()) << "detection " << k;
    EXPECT_GT(kept[k].size(), 0u) << "detection " << k;
    for (std::size_t i = 0; i < kept[k].size(); ++i) {
      EXPECT_EQ(kept[k][i].box, every_time[k][i].box) << "detection " << k << ", face " << i;
      EXPECT_EQ(kept[k][i].rejected, every_time[k][i].rejected) << "detection " << k;
      EXPECT_EQ(kept[k][i].reason, every_time[k][i].reason) << "detection " << k;
    }
  }
}

// A late detection (the real-time clock, latency_steps) can reseed the tracks after the frame
// it came from: the tracks then have no point in that frame to anchor them to it, and the
// detection's point stands rather than theirs (a CamShift window is not the face's box); once
// a detection comes in a frame the tracks have, the tracks carry the target from there.
TEST(TriangulateComponent, UntilTheTracksAreAnchoredToADetectionItsPointStands) {
  const scene::Scene& scene = Scene();
  const Eigen::Vector3d face = FaceCentreAt(scene, Astronaut(), 0.0);
  const head::IkResult look = head::SolveFixation(*scene.robot()->head.AppendixAHead(), face);
  ASSERT_TRUE(look.reachable());
  const auto at_frame = [](const std::shared_ptr<const Image>& image, int64_t frame) {
    auto copy = std::make_shared<Image>(*image);
    copy->metadata().frame_index = frame;
    return std::shared_ptr<const Image>(copy);
  };
  const std::shared_ptr<const Image> left = RenderOne(kScene, "left", look.joints, {});
  const std::shared_ptr<const Image> right = RenderOne(kScene, "right", look.joints, {});
  const std::optional<cv::Rect> left_box = AcceptedBox(DetectWhole(left));
  const std::optional<cv::Rect> right_box = AcceptedBox(DetectWhole(right));
  ASSERT_TRUE(left_box && right_box);

  const auto track = [](const std::shared_ptr<const Image>& image, const cv::Rect& box) {
    TrackMessage t;  // a window slid down the face, as CamShift's does onto the neck
    t.image = image;
    t.target_id = 0;
    t.tracking = true;
    t.window = box + cv::Point(0, box.height / 4);
    t.center = {t.window.x + 0.5 * t.window.width, t.window.y + 0.5 * t.window.height};
    return t;
  };
  const auto selection = [&](int64_t frame, bool fresh) {
    SelectionMessage s;
    s.valid = true;
    s.target_id = 0;
    s.p_W = face;  // the detections' point
    s.frame_index = frame;
    s.boxes_fresh = fresh;
    s.left_box = *left_box;
    s.right_box = *right_box;
    return s;
  };
  const auto step = [&](runtime::Component& c, int64_t k, int64_t track_frame,
                        const SelectionMessage& s) {
    auto target = Capture<TargetMessage>(c, "target");
    In<TrackMessage>(c, "left").Deliver(track(at_frame(left, track_frame), *left_box));
    In<TrackMessage>(c, "right").Deliver(track(at_frame(right, track_frame), *right_box));
    In<SelectionMessage>(c, "selection").Deliver(s);
    c.Step(At(k));
    EXPECT_TRUE(target->has_value());
    return target->value_or(TargetMessage{});
  };
  // The tracks' own point, for scale: centimetres from the face centre.
  auto raw = Make("vision.triangulate", {{"prefer", "tracks"}});
  const TargetMessage tracks_alone = step(*raw, 0, 8, selection(6, true));
  ASSERT_EQ(tracks_alone.source, "tracks");
  EXPECT_GT((tracks_alone.p_W - face).norm(), 0.01);

  auto triangulate = Make("vision.triangulate", json::object());
  // A detection of frame 6 arrives while the tracks, reseeded from it, are at frame 8.
  const TargetMessage late = step(*triangulate, 0, 8, selection(6, true));
  EXPECT_EQ(late.source, "selection");
  EXPECT_LT((late.p_W - face).norm(), 1e-9);
  const TargetMessage between = step(*triangulate, 1, 9, selection(9, false));
  EXPECT_EQ(between.source, "selection");  // still no anchor
  EXPECT_LT((between.p_W - face).norm(), 1e-9);
  // A detection of frame 9, a frame the tracks have: anchored from then on.
  EXPECT_EQ(step(*triangulate, 2, 10, selection(9, true)).source, "tracks");
  const TargetMessage anchored = step(*triangulate, 3, 11, selection(11, false));
  EXPECT_EQ(anchored.source, "tracks");
  EXPECT_LT((anchored.p_W - face).norm(), 1e-6);  // the tracks moved by the detection's offset
}

// The track follows the selected face, and nothing else: when attention moves to a place it
// has no detection of yet, or explores (its home point, not a face), the last face's track
// ends, so that neither triangulation nor the detectors keep following a face attention left.
TEST(CamShiftComponent, EndsTheLastFacesTrackWhenAttentionMovesOnOrExplores) {
  const std::shared_ptr<const Image> image = LeftEyeOnTheAstronaut();
  ASSERT_TRUE(image);
  const std::optional<cv::Rect> face = AcceptedBox(DetectWhole(image));
  ASSERT_TRUE(face);

  auto tracker = Make("vision.camshift", {{"eye", "left"}});
  auto track = Capture<TrackMessage>(*tracker, "track");
  const auto step = [&](const SelectionMessage& selection, int64_t k) {
    In<runtime::ImageMessage>(*tracker, "image").Deliver(runtime::ImageMessage{image});
    In<SelectionMessage>(*tracker, "selection").Deliver(selection);
    tracker->Step(At(k));
    return **track;
  };
  SelectionMessage selected;  // the astronaut, detected in this image
  selected.valid = true;
  selected.target_id = 0;
  selected.boxes_fresh = true;
  selected.frame_index = image->metadata().frame_index;
  selected.left_box = selected.right_box = *face;
  EXPECT_TRUE(step(selected, 0).tracking);
  EXPECT_TRUE(step(selected, 1).tracking);  // the same target: tracked on
  SelectionMessage elsewhere = selected;    // another place, no detection of it yet
  elsewhere.target_id = 1;
  elsewhere.boxes_fresh = false;
  const TrackMessage waiting = step(elsewhere, 2);
  EXPECT_FALSE(waiting.tracking);
  EXPECT_EQ(waiting.target_id, 1);
  EXPECT_TRUE(step(selected, 3).tracking);  // the astronaut again, detected: tracked again
  SelectionMessage exploring = selected;    // home, straight ahead: not a face
  exploring.target_id = 2;
  exploring.exploring = true;
  exploring.boxes_fresh = false;
  const TrackMessage none = step(exploring, 4);
  EXPECT_FALSE(none.tracking);
  EXPECT_EQ(none.target_id, -1);
}

// On the real-time clock detection runs on a thread of its own (the loop goes on at camera
// rate): the step that brings the image emits nothing, a later one emits the faces of that
// image, the same as a detection within the step. realtime_thread: false detects within it.
TEST(FaceDetectorComponent, OnTheRealTimeClockDetectsOnAThreadOfItsOwn) {
  const std::shared_ptr<const Image> image = LeftEyeOnTheAstronaut();
  ASSERT_TRUE(image);
  const auto realtime = [](int64_t step) {
    runtime::StepContext context = At(step);
    context.realtime = true;
    return context;
  };
  auto within = Make("vision.face_detector", {{"realtime_thread", false}});
  auto want = Capture<FacesMessage>(*within, "faces");
  In<runtime::ImageMessage>(*within, "image").Deliver(runtime::ImageMessage{image});
  within->Step(realtime(0));
  ASSERT_TRUE(want->has_value());  // within the step
  ASSERT_FALSE((*want)->faces.empty());

  auto threaded = Make("vision.face_detector", json::object());
  auto got = Capture<FacesMessage>(*threaded, "faces");
  In<runtime::ImageMessage>(*threaded, "image").Deliver(runtime::ImageMessage{image});
  threaded->Step(realtime(0));
  EXPECT_FALSE(got->has_value());  // started, not waited for
  int64_t step = 1;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!got->has_value() && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    threaded->Step(realtime(step++));  // no new image: only collects
  }
  ASSERT_TRUE(got->has_value());
  EXPECT_EQ((*got)->image, image);  // stamped with the frame it came from
  ASSERT_EQ((*got)->faces.size(), (*want)->faces.size());
  for (std::size_t i = 0; i < (*want)->faces.size(); ++i) {
    EXPECT_EQ((*got)->faces[i].box, (*want)->faces[i].box) << i;
    EXPECT_EQ((*got)->faces[i].rejected, (*want)->faces[i].rejected) << i;
  }
  threaded->Stop();
}

// On its own thread in real time (the GUI, demo --realtime) the detector does not use the
// discovery lane, but its whole-image searches for the other faces take the lane's pyramid
// level (discovery_pyramid_level) as the lane's would.
TEST(FaceDetectorComponent, OnItsOwnThreadSearchesTheWholeImageAtTheLanesLevel) {
  const std::shared_ptr<const Image> image = LeftEyeOnTheAstronaut();
  ASSERT_TRUE(image);
  const auto full = Boxes(DetectWhole(image, {{"scale_factor", 1.2}}));
  const auto half = Boxes(DetectWhole(image, {{"scale_factor", 1.2}, {"pyramid_level", 1}}));
  ASSERT_FALSE(half.empty());
  ASSERT_NE(full, half);  // else this test could not tell them apart

  const auto realtime = [](int64_t step) {
    runtime::StepContext context = At(step);
    context.realtime = true;
    return context;
  };
  const auto threaded = [&](int lane_latency) {
    auto detector = Make("vision.face_detector", {{"track_region_scale", 2.0},
                                                  {"full_scan_every", 1},
                                                  {"new_target_scans", 0},
                                                  {"discovery_scale_factor", 1.2},
                                                  {"discovery_latency_steps", lane_latency},
                                                  {"discovery_pyramid_level", 1}});
    auto faces = Capture<FacesMessage>(*detector, "faces");
    In<TrackMessage>(*detector, "track").Deliver(TrackOnTheSky());
    In<runtime::ImageMessage>(*detector, "image").Deliver(runtime::ImageMessage{image});
    detector->Step(realtime(0));
    int64_t step = 1;
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!faces->has_value() && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      detector->Step(realtime(step++));  // no new image: only collects
    }
    detector->Stop();
    EXPECT_TRUE(faces->has_value());
    return Boxes(faces->value_or(FacesMessage{}));
  };
  EXPECT_EQ(threaded(4), half);  // the lane's level
  EXPECT_EQ(threaded(0), full);  // no lane: pyramid_level
}

TEST(SimCameras, TheHeadsMotionBlursTheEyeImages) {
  const std::string portraits = std::string(SACCADE_SOURCE_DIR) + "/scenes/portraits.yaml";
  const head::JointState still = head::JointState::Popeye(0.0, 0.0, 0.0, 0.0);
  const auto sharp = RenderOne(portraits, "left", still, still);
  const auto blurred = RenderOne(portraits, "left", still,
                                 head::JointState::Popeye(3.0, 0.0, 0.0, 0.0));  // 170 deg/s
  EXPECT_EQ(blurred->metadata().joints[0], 0.0);
  // 3 rad/s over 8 ms sweeps 0.024 rad, ~31 px: the edges' energy falls several-fold.
  EXPECT_LT(Sharpness(*blurred), 0.5 * Sharpness(*sharp));
}

// The pre-processing components give exactly what the vision classes give (those are tested
// against OpenCV in tests/vision), with the frame's metadata.
TEST(PreprocessingComponents, GiveWhatTheVisionClassesGive) {
  // The bench scene's eye cameras have a radtan lens (k1 = -0.2), so undistortion has work.
  const std::string bench = std::string(SACCADE_SOURCE_DIR) + "/scenes/bench.yaml";
  const head::JointState still = head::JointState::Popeye(0.0, 0.0, 0.0, 0.0);
  const auto image = RenderOne(bench, "left", still, still);
  ASSERT_EQ(testing_helpers::DistortionName(image->metadata()), "radtan");
  const auto run = [&](const std::string& type, const json& params) {
    auto c = Make(type, params);
    auto out = Capture<runtime::ImageMessage>(*c, "image");
    In<runtime::ImageMessage>(*c, "image").Deliver(runtime::ImageMessage{image});
    c->Step(At(0));
    EXPECT_TRUE(*out) << type;
    return (*out)->image;
  };
  const auto equal = [](const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::equal(a.data(), a.data() + a.size_bytes(), b.data());
  };
  vision::MedianFilter::Options median;
  median.kernel_size = 5;
  EXPECT_TRUE(equal(*run("vision.median", {{"kernel_size", 5}}),
                    vision::MedianFilter(median).Apply(*image)));
  vision::Sharpener::Options sharpen;
  sharpen.amount = 1.5;
  sharpen.sigma = 2.0;
  EXPECT_TRUE(equal(*run("vision.sharpen", {{"amount", 1.5}, {"sigma", 2.0}}),
                    vision::Sharpener(sharpen).Apply(*image)));
  const auto undistorted = run("vision.undistort", json::object());
  EXPECT_TRUE(
      equal(*undistorted, vision::Undistorter(vision::CameraModelOf(*image)).Apply(*image)));
  EXPECT_EQ(testing_helpers::DistortionName(undistorted->metadata()), "none");
  EXPECT_EQ(undistorted->metadata().frame_index, image->metadata().frame_index);
}

CandidatesMessage Candidates(double time, std::vector<Eigen::Vector3d> points) {
  CandidatesMessage m;
  m.time = time;
  for (const Eigen::Vector3d& p : points) m.candidates.push_back({p, {}, {}, p.norm(), 0, 0, 0.15});
  return m;
}

// Attention: the closest face first; once fixated for fixation_time_s, the next; when nothing
// is left, home.
TEST(AttentionComponent, VisitsTheClosestFirstThenTheNextThenGoesHome) {
  const scene::Scene& scene = Scene();
  auto attention = Make("vision.attention",
                        {{"scene", kScene}, {"fixation_time_s", 0.2}, {"explore_after_s", 0.1}});
  auto selection = Capture<SelectionMessage>(*attention, "selection");
  const Eigen::Vector3d near(1.5, 0.3, 1.2), far(3.0, -0.4, 1.3);
  std::vector<int64_t> ids;
  std::vector<Eigen::Vector3d> looked_at;
  for (int64_t step = 0; step < 40; ++step) {
    const double t = At(step).time;
    // The head is on whatever was selected last (as if the motors were instant).
    if (*selection && (*selection)->valid) {
      JointStateMessage joints;
      joints.positions = joints.velocities = joints.targets = joints.target_velocities =
          head::JointState::Popeye(0, 0, 0, 0);
      joints.positions =
          head::SolveFixation(*scene.robot()->head.AppendixAHead(), (*selection)->p_W).joints;
      joints.arrived = true;
      In<JointStateMessage>(*attention, "joints").Deliver(joints);
    }
    // Both faces are seen for the first 25 steps, then nothing.
    In<CandidatesMessage>(*attention, "candidates")
        .Deliver(step < 25 ? Candidates(t, {far, near}) : Candidates(t, {}));
    attention->Step(At(step));
    attention->inputs()[0]->MarkSeen();
    if (ids.empty() || ids.back() != (*selection)->target_id) {
      ids.push_back((*selection)->target_id);
      looked_at.push_back((*selection)->p_W);
    }
  }
  ASSERT_GE(ids.size(), 3u);
  EXPECT_LT((looked_at[0] - near).norm(), 1e-12);  // closest first
  EXPECT_LT((looked_at[1] - far).norm(), 1e-12);   // then the next
  EXPECT_TRUE((*selection)->exploring);            // nothing left: home
  EXPECT_EQ((*selection)->suppressed_W.size(), 2u);
}

// A saccade lands where the sightings during it put the face; the fixation (and its dwell)
// begins only once this step's sighting agrees with where the eyes point, within
// onset_tolerance_deg. Once begun, a sighting's jitter does not end it.
TEST(AttentionComponent, AFixationBeginsWhereThisStepsSightingAgreesWithTheEyes) {
  const scene::Scene& scene = Scene();
  const Eigen::Vector3d face(2.0, 0.2, 1.2);
  // A point `deg` degrees beside the face, seen from the head (a turn about the vertical).
  const auto beside = [&](double deg) {
    const Eigen::Vector3d viewer =
        head::ForwardKinematics(*scene.robot()->head.AppendixAHead(),
                                head::PopeyeJoints::From(scene.robot()->initial_joints))
            .X_WC.translation();
    return Eigen::Vector3d(
        viewer + Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()) * (face - viewer));
  };
  // The head on `on`, at rest; the step's sighting at `seen`. Returns whether it fixates.
  const auto run = [&](double onset_deg,
                       const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& steps) {
    auto attention =
        Make("vision.attention", {{"scene", kScene}, {"onset_tolerance_deg", onset_deg}});
    auto selection = Capture<SelectionMessage>(*attention, "selection");
    std::vector<bool> fixating;
    for (std::size_t step = 0; step < steps.size(); ++step) {
      JointStateMessage joints;
      joints.positions = joints.velocities = joints.targets = joints.target_velocities =
          head::JointState::Popeye(0, 0, 0, 0);
      joints.positions =
          head::SolveFixation(*scene.robot()->head.AppendixAHead(), steps[step].first).joints;
      joints.arrived = true;
      In<JointStateMessage>(*attention, "joints").Deliver(joints);
      In<CandidatesMessage>(*attention, "candidates")
          .Deliver(Candidates(At(step).time, {steps[step].second}));
      attention->Step(At(step));
      attention->inputs()[0]->MarkSeen();
      fixating.push_back((*selection)->fixating);
    }
    return fixating;
  };
  // Step 0 selects the face as seen in the saccade (0.4 deg off, 14 mm at 2 m); at step 1 the
  // head has landed there and sees the face where it is; at step 2 the head is on it; at
  // steps 3 and 4 the sightings jitter by 0.3 deg.
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> steps = {{face, beside(0.4)},
                                                                          {beside(0.4), face},
                                                                          {face, face},
                                                                          {face, beside(0.3)},
                                                                          {beside(0.3), face}};
  EXPECT_EQ(run(0.1, steps), std::vector<bool>({false, false, true, true, true}));
  // Without the onset check the landing counts as a fixation.
  EXPECT_EQ(run(180.0, steps), std::vector<bool>({false, true, true, true, true}));
}

TEST(SimHead, CommandsBeyondTheLimitsAreClampedAndCountedNeverExceeded) {
  const scene::Scene& scene = Scene();
  auto head_component = Make("sim.head", {{"scene", kScene}});
  auto joints = Capture<JointStateMessage>(*head_component, "joints");
  head_component->Start();
  JointCommand command;
  command.positions = command.velocities = head::JointState::Popeye(0, 0, 0, 0);
  command.positions = head::JointState::Popeye(
      3.0, -2.0, 0.0, 0.0);  // pan 172 deg, tilt -115 deg: beyond the limits
  In<JointCommand>(*head_component, "command").Deliver(command);
  const auto& limits = scene.robot()->head;
  for (int64_t step = 0; step < 100; ++step) {
    head_component->Step(At(step));
    head_component->inputs()[0]->MarkSeen();
    EXPECT_LE((*joints)->positions[0], limits.joint(0).limits.max + 1e-12);
    EXPECT_GE((*joints)->positions[1], limits.joint(1).limits.min - 1e-12);
    EXPECT_LE(std::abs((*joints)->velocities[0]), limits.joint(0).limits.max_velocity + 1e-9);
  }
  EXPECT_TRUE((*joints)->arrived);
  EXPECT_DOUBLE_EQ((*joints)->positions[0], limits.joint(0).limits.max);
  EXPECT_EQ((*joints)->clamped_commands, 2);        // pan and tilt
  EXPECT_NEAR((*joints)->time, 100 * 0.04, 1e-12);  // the state at the next step's time

  command.positions[1] = std::nan("");
  In<JointCommand>(*head_component, "command").Deliver(command);
  try {
    head_component->Step(At(100));
    FAIL() << "a NaN command was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("tilt"), std::string::npos) << e.what();
  }
}

// The head's methods: state, move (clamped, NaN refused) and stop, by JSON as a script would.
TEST(SimHead, MethodsReadMoveAndStopTheHead) {
  RegisterComponents();
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(
      "clock: {mode: simulated, step: 0.04, steps: 10}\ncomponents:\n"
      "  - {name: head, type: sim.head, params: {scene: astronaut_and_cat.yaml}}\n",
      std::string(SACCADE_SOURCE_DIR) + "/scenes/p.yaml");
  runtime::RunPipeline(pipeline);  // started (and stopped) once: the motors exist
  const json moved =
      pipeline.Call("head", "move",
                    {{"time", 0.0},
                     {"positions", {{"pan", 0.5}, {"tilt", 9.0}, {"left", 0.0}, {"right", 0.0}}},
                     {"velocities", {{"pan", 0.0}, {"tilt", 0.0}, {"left", 0.0}, {"right", 0.0}}},
                     {"target_id", -1}});
  EXPECT_DOUBLE_EQ(moved["targets"]["pan"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(moved["targets"]["tilt"].get<double>(),
                   Scene().robot()->head.joint(1).limits.max);  // clamped
  EXPECT_EQ(moved["clamped_commands"], 1);
  const json stopped = pipeline.Call("head", "stop", json::object());
  EXPECT_EQ(stopped["targets"], stopped["positions"]);  // at rest: holds where it is
  try {
    json bad = moved;
    bad["positions"] = {{"pan", 0.5}, {"tilt", "down"}, {"left", 0.0}, {"right", 0.0}};
    pipeline.Call("head", "move", bad);
    FAIL() << "accepted a non-numeric tilt";
  } catch (const runtime::MethodError& e) {
    EXPECT_NE(std::string(e.what()).find("field 'tilt'"), std::string::npos) << e.what();
  }
  EXPECT_EQ(pipeline.Call("head", "state", json::object())["targets"], stopped["targets"]);
}

// Pursuit: a target moving at constant velocity gets joint velocities that follow it.
TEST(FixationComponent, AMovingTargetGetsPursuitVelocitiesThatFollowIt) {
  const scene::Scene& scene = Scene();
  auto fixation = Make("control.fixation", {{"scene", kScene}, {"velocity_smoothing", 1.0}});
  auto command = Capture<JointCommand>(*fixation, "command");
  const Eigen::Vector3d v(0.0, 0.2, 0.0);  // 0.2 m/s to the left
  for (int64_t step = 0; step < 5; ++step) {
    TargetMessage target;
    target.valid = true;
    target.target_id = 1;
    target.time = At(step).time;
    target.p_W = Eigen::Vector3d(2.0, 0.0, 1.2) + v * target.time;
    In<TargetMessage>(*fixation, "target").Deliver(target);
    fixation->Step(At(step));
  }
  ASSERT_TRUE(*command);
  EXPECT_TRUE((*command)->pursuit());
  // Pan rate of a point 2 m ahead moving sideways at 0.2 m/s: ~0.1 rad/s (to the left, > 0).
  const double t = At(4).time;
  const double expected = 0.2 * 2.0 / (4.0 + std::pow(0.2 * t, 2));
  EXPECT_NEAR((*command)->velocities[0], expected, 0.01 * expected);
  const auto& head = scene.robot()->head;
  const head::HeadFrames frames = head::ForwardKinematics(
      *head.AppendixAHead(), head::PopeyeJoints::From((*command)->positions));
  ASSERT_TRUE(frames.p_WFixation);
  EXPECT_LT((*frames.p_WFixation - (Eigen::Vector3d(2.0, 0.0, 1.2) + v * t)).norm(), kIkToleranceM);
}

TEST(ComponentParams, UnknownMissingAndOutOfRangeParametersAreNamed) {
  const auto message = [](const std::string& type, const json& params) {
    try {
      Make(type, params);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message("vision.face_detector", {{"min_neighbours", 3}}),
            "unknown parameter 'min_neighbours' (known: cascade, discovery_latency_steps, "
            "discovery_pyramid_level, discovery_scale_factor, full_scan_every, "
            "keep_target_verdict, latency_steps, max_size_px, min_neighbors, min_size_px, "
            "new_target_scans, partner_max_depth_m, "
            "partner_min_depth_m, pyramid_level, realtime_thread, recheck_every, "
            "recheck_phase, region_pyramid_level, region_size_factor, reject_cats, "
            "require_eyes, scale_factor, track_region_scale)");
  EXPECT_EQ(
      message("vision.face_detector", {{"partner_min_depth_m", 5}, {"partner_max_depth_m", 2}}),
      "partner_min_depth_m (5) must be less than partner_max_depth_m (2)");
  EXPECT_EQ(message("vision.camshift", json::object()),
            "parameter 'eye' is required: one of left, right (the eye whose image and box it "
            "tracks)");
  // No scene: neither the parameter nor the pipeline (resources.h) names one.
  EXPECT_EQ(message("sim.head", json::object()),
            "no scene: name it once at the top of the pipeline or hardware file (scene: FILE), or "
            "give this component the parameter 'scene'");
  EXPECT_EQ(message("vision.attention", {{"scene", kScene}, {"fixation_time_s", -1}}),
            "parameter 'fixation_time_s': expected a number in (0, 1000000], got -1");
  EXPECT_EQ(message("sim.cameras", {{"scene", kScene}, {"cameras", {"left", "middle"}}}),
            "parameter 'cameras': scene '" + kScene + "' has no camera 'middle'");
}

// In a pipeline file: the error names the file, the line and the component.
TEST(ComponentParams, PipelineErrorsNameTheFileLineAndComponent) {
  RegisterComponents();
  const std::string file = std::string(SACCADE_SOURCE_DIR) + "/pipelines/bad.yaml";
  const auto error = [&](const std::string& yaml) {
    try {
      runtime::Pipeline::LoadString(yaml, file);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string head = "clock: {mode: simulated, step: 0.04, steps: 1}\ncomponents:\n";
  EXPECT_EQ(
      error(head + "  - {name: d, type: vision.face_detector, params: {min_neighbors: -2}}\n"),
      file +
          ":3: components[0].params: component 'd' (vision.face_detector): parameter "
          "'min_neighbors': expected an integer in [0, 1000], got -2");
  // Faces into an image input: the types are named.
  const std::string wrong =
      error(head +
            "  - {name: c, type: sim.cameras, params: {scene: ../scenes/astronaut_and_cat.yaml}}\n"
            "  - {name: d, type: vision.face_detector, inputs: {image: c.left}}\n"
            "  - {name: e, type: vision.face_detector, inputs: {image: d.faces}}\n");
  EXPECT_NE(wrong.find(":5:"), std::string::npos) << wrong;
  EXPECT_NE(wrong.find("vision.faces"), std::string::npos) << wrong;
  EXPECT_NE(wrong.find("runtime.image"), std::string::npos) << wrong;
}

}  // namespace
}  // namespace saccade::components
