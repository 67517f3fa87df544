// Stereo rectification (Bouguet's R1, R2) against OpenCV's cv::stereoRectify, and a ROS stereo
// pair's pose (R, T) read back from the rectification and projection matrices OpenCV computes,
// as ROS's camera_calibration writes them.

#include "saccade/geometry/stereo_rectification.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <random>
#include <string>

#include "saccade/core/error.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/geometry/calibration_report.h"

namespace saccade::geometry {
namespace {

// Both compute the same products of the same rotations in double; the residue is the order
// of operations in Rodrigues' formula (OpenCV's own code against Eigen's AngleAxis).
constexpr double kRotationTolerance = 1e-12;
// R and T through a ROS file: the matrices are written with 17 significant digits, then
// R = R2^T R1 and T = R2^T t' are formed again.
constexpr double kRosPairTolerance = 1e-12;

// A random vergence-head-like pose: the right camera 5-15 cm to the right, turned by up to 20
// degrees about a random axis (mostly about y: vergence), or below the left (vertical pairs).
void RandomPose(std::mt19937& rng, bool vertical, Eigen::Matrix3d* R, Eigen::Vector3d* T) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3 * u(rng), 1.0, 0.3 * u(rng)).normalized();
  *R = Eigen::AngleAxisd(0.35 * u(rng), axis).toRotationMatrix();
  const double b = 0.05 + 0.05 * (u(rng) + 1.0);
  *T = vertical ? Eigen::Vector3d(0.01 * u(rng), -b, 0.01 * u(rng))
                : Eigen::Vector3d(-b, 0.01 * u(rng), 0.01 * u(rng));
}

cv::Matx33d Cv(const Eigen::Matrix3d& m) {
  cv::Matx33d out;
  cv::eigen2cv(m, out);
  return out;
}

TEST(StereoRectification, AgreesWithOpenCvsStereoRectifyOnRandomPoses) {
  std::mt19937 rng(7);
  const cv::Matx33d K(500, 0, 320, 0, 500, 240, 0, 0, 1);
  for (int i = 0; i < 200; ++i) {
    const bool vertical = i % 4 == 3;
    Eigen::Matrix3d R;
    Eigen::Vector3d T;
    RandomPose(rng, vertical, &R, &T);
    cv::Mat R1, R2, P1, P2, Q;
    cv::stereoRectify(K, cv::noArray(), K, cv::noArray(), cv::Size(640, 480), Cv(R),
                      cv::Vec3d(T.x(), T.y(), T.z()), R1, R2, P1, P2, Q);
    const StereoRectification rect = RectifyStereo(R, T);
    Eigen::Matrix3d r1, r2;
    cv::cv2eigen(R1, r1);
    cv::cv2eigen(R2, r2);
    ASSERT_LT((rect.R1 - r1).cwiseAbs().maxCoeff(), kRotationTolerance) << "pose " << i;
    ASSERT_LT((rect.R2 - r2).cwiseAbs().maxCoeff(), kRotationTolerance) << "pose " << i;
    EXPECT_EQ(rect.vertical, vertical) << "pose " << i;
    // Rectified, the baseline lies along one axis: the other two of T_rect vanish, and
    // OpenCV's P2 holds it times the new focal length.
    const int axis = vertical ? 1 : 0;
    EXPECT_NEAR(rect.T_rect.norm(), std::abs(rect.T_rect[axis]), 1e-12);
    EXPECT_NEAR(P2.at<double>(axis, 3), P2.at<double>(axis, axis) * rect.T_rect[axis], 1e-9);
  }
}

TEST(StereoRectification, RefusesWhatIsNotAStereoPose) {
  EXPECT_THROW(RectifyStereo(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()),
               InvalidArgument);
  EXPECT_THROW(RectifyStereo(2.0 * Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitX()),
               InvalidArgument);
}

std::string RosMatrix(const char* key, const cv::Mat& m) {
  std::string text = std::string(key) + ":\n  rows: " + std::to_string(m.rows) +
                     "\n  cols: " + std::to_string(m.cols) + "\n  data: [";
  for (int r = 0; r < m.rows; ++r) {
    for (int c = 0; c < m.cols; ++c) {
      char number[40];
      std::snprintf(number, sizeof(number), "%.17g", m.at<double>(r, c));
      text += std::string(r + c > 0 ? ", " : "") + number;
    }
  }
  return text + "]\n";
}

// A camera_info YAML as camera_calibration writes a stereo camera's.
std::string RosCameraInfo(const std::string& name, const cv::Matx33d& K, const cv::Mat& R,
                          const cv::Mat& P) {
  return "image_width: 640\nimage_height: 480\ncamera_name: " + name + "\n" +
         RosMatrix("camera_matrix", cv::Mat(K)) +
         "distortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n"
         "  data: [0.01, -0.02, 0, 0, 0]\n" +
         RosMatrix("rectification_matrix", R) + RosMatrix("projection_matrix", P);
}

TEST(RosStereoPair, ItsRectificationAndProjectionGiveBackThePose) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("saccade_ros_pair_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::mt19937 rng(11);
  const cv::Matx33d K1(510, 0, 318, 0, 505, 242, 0, 0, 1), K2(500, 0, 322, 0, 498, 238, 0, 0, 1);
  for (int i = 0; i < 40; ++i) {
    Eigen::Matrix3d R;
    Eigen::Vector3d T;
    RandomPose(rng, i % 4 == 3, &R, &T);
    cv::Mat R1, R2, P1, P2, Q;
    cv::stereoRectify(K1, cv::noArray(), K2, cv::noArray(), cv::Size(640, 480), Cv(R),
                      cv::Vec3d(T.x(), T.y(), T.z()), R1, R2, P1, P2, Q);
    std::ofstream(dir / "left.yaml") << RosCameraInfo("narrow_stereo/left", K1, R1, P1);
    std::ofstream(dir / "right.yaml") << RosCameraInfo("narrow_stereo/right", K2, R2, P2);
    const StereoCalibration pair = ReadRosStereoPair(dir / "left.yaml", dir / "right.yaml");
    EXPECT_LT((pair.R - R).cwiseAbs().maxCoeff(), kRosPairTolerance) << "pose " << i;
    EXPECT_LT((pair.T - T).cwiseAbs().maxCoeff(), kRosPairTolerance) << "pose " << i;
    EXPECT_DOUBLE_EQ(pair.left.intrinsics().fx(), 510);
    EXPECT_DOUBLE_EQ(pair.right.intrinsics().fx(), 500);
  }
  // The report of the pair: both cameras by name, the baseline.
  const nlohmann::json report =
      CalibrationReportJson({dir / "left.yaml", dir / "right.yaml", {}, {}, 0.01, 100.0});
  EXPECT_EQ(report["left"]["name"], "narrow_stereo/left");
  EXPECT_EQ(report["right"]["name"], "narrow_stereo/right");
  const StereoCalibration last = ReadRosStereoPair(dir / "left.yaml", dir / "right.yaml");
  EXPECT_NEAR(report["baseline"].get<double>(), last.T.norm(), 1e-15);

  // A monocular camera's P = [K | 0] has no baseline: not the right camera of a pair.
  cv::Mat P0 = cv::Mat::zeros(3, 4, CV_64F);
  cv::Mat(K2).copyTo(P0(cv::Rect(0, 0, 3, 3)));
  std::ofstream(dir / "mono.yaml") << RosCameraInfo("mono", K2, cv::Mat::eye(3, 3, CV_64F), P0);
  try {
    ReadRosStereoPair(dir / "left.yaml", dir / "mono.yaml");
    ADD_FAILURE() << "a monocular camera_info was taken as a pair's right camera";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("mono.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("projection_matrix"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no baseline"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace saccade::geometry
