// Stereo association and triangulation on the eye cameras' renders of
// scenes/astronaut_and_cat.yaml: the astronaut's face detected in both eyes, associated, and
// triangulated near the true face centre (the centre of the face box in her picture's own
// texture, placed in the world by the picture's pose: see portraits.h).
#include "saccade/vision/stereo_associator.h"

#include <gtest/gtest.h>

#include <iostream>
#include <vector>

#include "portraits.h"
#include "saccade/core/error.h"
#include "saccade/vision/face_detector.h"
#include "saccade/vision/image_camera.h"

namespace saccade::vision::testing {
namespace {

// Tolerance of the triangulated face centre, metres, at ~2.2 m. Depth from disparity:
// dZ = Z^2 dd / (f b) = 2.2^2 * dd / (1290 * 0.2) = 0.019 m per pixel of disparity error; the
// two eyes' boxes of one face differ in centre by up to ~1.5 px (the cascade's pyramid
// steps of 10 % quantise box position and size), so depth may be off ~3 cm; sideways a pixel
// is only 2.2 / 1290 = 1.7 mm. The face centre itself is the texture's cascade box centre, and
// the rendered box differs from it by a similar pixel or two. 5 cm covers that with margin and
// still catches any frame, sign or distortion error (each moves the point decimetres).
constexpr double kMaxFaceErrorM = 0.05;

std::vector<StereoObservation> AcceptedFaces(FaceDetector& detector, const Image& image) {
  std::vector<StereoObservation> out;
  for (const FaceDetection& face : detector.Detect(image)) {
    if (!face.rejected) out.push_back(StereoObservation::FromBox(face.box));
  }
  return out;
}

TEST(StereoAssociator, TriangulatesTheDetectedFaceNearTheTrueFaceCentre) {
  const Eigen::Vector3d truth = FaceCentreWorld("astronaut");
  FaceDetector detector;
  StereoAssociator associator;
  // The head fixating the face, and looking 0.25 m beside, above and below it: the face off
  // the image centre, where distortion and vergence matter.
  for (const Eigen::Vector3d& offset :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0.25, 0), Eigen::Vector3d(0, -0.25, 0),
        Eigen::Vector3d(0, 0, 0.2), Eigen::Vector3d(0, 0, -0.2)}) {
    const StereoFrame frame = RenderFixating(truth + offset);
    const std::vector<StereoObservation> left = AcceptedFaces(detector, frame.left);
    const std::vector<StereoObservation> right = AcceptedFaces(detector, frame.right);
    const std::vector<StereoMatch> matches =
        associator.Associate(frame.left, left, frame.right, right);
    ASSERT_EQ(matches.size(), 1u) << "offset " << offset.transpose();
    const StereoMatch& m = matches.front();
    const double error = (m.p_W - truth).norm();
    std::cout << "offset " << offset.transpose() << ": error " << error * 1000 << " mm ("
              << (m.p_W - truth).transpose() << "), reprojection " << m.reprojection_px
              << " px, gap " << m.gap_m * 1000 << " mm, depth " << m.depth_m << " m, width "
              << m.width_m << " m\n";
    EXPECT_LT(error, kMaxFaceErrorM) << "offset " << offset.transpose();
  }
}

// Exact observations (the true face centres projected through each image's own camera) are
// associated whatever their order, triangulate back to the points, and the astronaut (2.2 m)
// is selected as closer than the cat (3 m).
TEST(StereoAssociator, AssociatesByGeometryAndSelectsTheClosest) {
  const Eigen::Vector3d astronaut = FaceCentreWorld("astronaut");
  const Eigen::Vector3d cat = PictureTexelToWorld("chelsea", 225, 150);
  const StereoFrame frame = RenderFixating(0.5 * (astronaut + cat));
  const auto observe = [](const Image& image, const Eigen::Vector3d& p_W) {
    const auto uv = CameraModelOf(image).Project(CameraPoseOf(image).inverse() * p_W);
    EXPECT_TRUE(uv.has_value());
    return StereoObservation{cv::Point2d(uv->x(), uv->y()), 0.0};
  };
  const std::vector<StereoObservation> left = {observe(frame.left, cat),
                                               observe(frame.left, astronaut)};
  const std::vector<StereoObservation> right = {observe(frame.right, astronaut),
                                                observe(frame.right, cat)};
  const std::vector<StereoMatch> matches =
      StereoAssociator().Associate(frame.left, left, frame.right, right);
  ASSERT_EQ(matches.size(), 2u);
  const std::optional<std::size_t> closest = SelectClosest(matches);
  ASSERT_TRUE(closest.has_value());
  const StereoMatch& a = matches[*closest];
  EXPECT_EQ(a.left, 1);
  EXPECT_EQ(a.right, 0);
  // Exact pixels: only the Unproject/Project round trip's rounding remains.
  EXPECT_LT((a.p_W - astronaut).norm(), 1e-6);
  EXPECT_LT(a.reprojection_px, 1e-6);
  const StereoMatch& c = matches[1 - *closest];
  EXPECT_EQ(c.left, 0);
  EXPECT_EQ(c.right, 1);
  EXPECT_LT((c.p_W - cat).norm(), 1e-6);
  EXPECT_LT(a.distance_m, c.distance_m);
}

// Box centres of one face differ between the eyes by pixels (the cascade's scale steps): with
// refine_disparity the right centre is found again by matching the left face patch, and the
// point comes back to the face's surface: at 2.2 m, 3 px of disparity is about 8 cm of depth.
TEST(StereoAssociator, RefiningTheDisparityUndoesABoxCentreError) {
  const Eigen::Vector3d astronaut = FaceCentreWorld("astronaut");
  const StereoFrame frame = RenderFixating(astronaut);
  const auto uv = [&](const Image& image) {
    const auto p = CameraModelOf(image).Project(CameraPoseOf(image).inverse() * astronaut);
    return StereoObservation{cv::Point2d(p->x(), p->y()), 100.0};
  };
  const std::vector<StereoObservation> left = {uv(frame.left)};
  StereoObservation shifted = uv(frame.right);
  shifted.center.x += 3.0;
  const std::vector<StereoObservation> right = {shifted};
  const std::vector<StereoMatch> raw =
      StereoAssociator().Associate(frame.left, left, frame.right, right);
  StereoAssociator::Options options;
  options.refine_disparity = true;
  const std::vector<StereoMatch> refined =
      StereoAssociator(options).Associate(frame.left, left, frame.right, right);
  ASSERT_EQ(raw.size(), 1u);
  ASSERT_EQ(refined.size(), 1u);
  const double raw_error = (raw[0].p_W - astronaut).norm();
  const double refined_error = (refined[0].p_W - astronaut).norm();
  std::cout << "3 px off: " << raw_error * 1e3 << " mm; refined: " << refined_error * 1e3
            << " mm\n";
  EXPECT_GT(raw_error, 0.04);
  EXPECT_LT(refined_error, 0.005);
  EXPECT_EQ(refined[0].left, 0);
  EXPECT_EQ(refined[0].right, 0);
}

// A left observation paired with the wrong right one is not a point both cameras see there:
// its reprojection error is far above the tolerance and it is not associated.
TEST(StereoAssociator, RejectsInconsistentPairs) {
  const Eigen::Vector3d astronaut = FaceCentreWorld("astronaut");
  const StereoFrame frame = RenderFixating(astronaut);
  const auto uv = [&](const Image& image, const Eigen::Vector3d& p_W) {
    const auto p = CameraModelOf(image).Project(CameraPoseOf(image).inverse() * p_W);
    return StereoObservation{cv::Point2d(p->x(), p->y()), 0.0};
  };
  // The right observation 40 px above where the left one's point projects: off the epipolar
  // line, no triangulation reprojects within 4 px.
  StereoObservation right = uv(frame.right, astronaut);
  right.center.y -= 40.0;
  const std::vector<StereoObservation> l = {uv(frame.left, astronaut)};
  const std::vector<StereoObservation> r = {right};
  EXPECT_TRUE(StereoAssociator().Associate(frame.left, l, frame.right, r).empty());
  // The physical-size check: a 100 px box at 2.2 m is ~0.17 m wide: outside 0.3 .. 0.5 m.
  StereoAssociator::Options options;
  options.min_width_m = 0.3;
  options.max_width_m = 0.5;
  std::vector<StereoObservation> l2 = l, r2 = {uv(frame.right, astronaut)};
  l2[0].width_px = r2[0].width_px = 100.0;
  EXPECT_TRUE(StereoAssociator(options).Associate(frame.left, l2, frame.right, r2).empty());
  EXPECT_EQ(StereoAssociator().Associate(frame.left, l2, frame.right, r2).size(), 1u);
}

TEST(StereoAssociator, BadOptionsSayWhatIsWrong) {
  StereoAssociator::Options o;
  o.max_reprojection_px = 0.0;
  try {
    StereoAssociator a(o);
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(),
                 "StereoAssociator::Options: max_reprojection_px 0, expected (0, 1000000]");
  }
  o = {};
  o.max_depth_m = 0.05;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_EQ(error,
            "StereoAssociator::Options: max_depth_m 0.050000, expected > min_depth_m (0.100000)");
  o = {};
  o.min_width_m = 0.3;
  o.max_width_m = 0.1;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("expected both 0 (off) or min < max"), std::string::npos);
}

TEST(StereoAssociator, AnImageWithoutACameraIsAnError) {
  const Image blank(64, 48, PixelFormat::kRgb8);  // K all zero
  const std::vector<StereoObservation> one = {{cv::Point2d(10, 10), 0.0}};
  EXPECT_THROW(StereoAssociator().Associate(blank, one, blank, one), InvalidArgument);
}

}  // namespace
}  // namespace saccade::vision::testing
