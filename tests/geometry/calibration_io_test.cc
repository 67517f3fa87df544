#include "saccade/geometry/calibration_io.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::geometry {
namespace {

namespace fs = std::filesystem;

// Calibration files from Debian's opencv-doc package (OpenCV's sample data).
const fs::path kOpenCvExamples = "/usr/share/doc/opencv-doc/examples";

// Every value must survive a file exactly: the writers print 17 significant digits and the
// readers parse correctly rounded, like cv::FileStorage (%.16e). Equality is bit-exact.

// The temporary directory of one test, removed afterwards.
class CalibrationIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string("saccade_calibration_io_") + std::to_string(::getpid()) + "_" +
                       info->test_suite_name() + "_" + info->name();
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    dir_ = fs::temp_directory_path() / name;
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path Path(const std::string& name) const { return dir_ / name; }

  fs::path WriteText(const std::string& name, const std::string& text) const {
    const fs::path path = Path(name);
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  fs::path dir_;
};

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("test template has no " + from);
  return text.replace(at, from.size(), to);
}

double Uniform(std::mt19937& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

// A random camera as calibrations produce them; `skew` only where OpenCV's files allow it.
CameraModel RandomCamera(std::mt19937& rng, DistortionModel model, int radtan_count = 5,
                         bool skew = false) {
  const int width = static_cast<int>(Uniform(rng, 320, 2048));
  const int height = static_cast<int>(Uniform(rng, 240, 1536));
  const double fx = Uniform(rng, 200, 2000);
  const Intrinsics intrinsics(
      width, height, fx, fx * Uniform(rng, 0.95, 1.05), width / 2.0 + Uniform(rng, -40, 40),
      height / 2.0 + Uniform(rng, -40, 40), skew ? Uniform(rng, -2, 2) : 0.0);
  std::vector<double> c;
  switch (model) {
    case DistortionModel::kNone:
      return CameraModel(intrinsics);
    case DistortionModel::kFisheye:
      for (int i = 0; i < 4; ++i) c.push_back(Uniform(rng, -0.05, 0.05));
      return CameraModel(intrinsics, Distortion::Fisheye(c));
    case DistortionModel::kRadialTangential:
      c = {Uniform(rng, -0.5, 0.5), Uniform(rng, -0.3, 0.3), Uniform(rng, -0.01, 0.01),
           Uniform(rng, -0.01, 0.01)};
      if (radtan_count >= 5) c.push_back(Uniform(rng, -0.1, 0.1));
      for (int i = 5; i < radtan_count; ++i) c.push_back(Uniform(rng, -0.3, 0.3));
      return CameraModel(intrinsics, Distortion::RadialTangential(c));
  }
  return CameraModel(intrinsics);
}

Eigen::Matrix3d RandomRotation(std::mt19937& rng) {
  const Eigen::Vector3d axis =
      Eigen::Vector3d(Uniform(rng, -1, 1), Uniform(rng, -1, 1), Uniform(rng, -1, 1)).normalized();
  return Eigen::AngleAxisd(Uniform(rng, -0.3, 0.3), axis).toRotationMatrix();
}

cv::Mat ToCv(const Eigen::Matrix3d& m) {
  cv::Mat out(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out.at<double>(r, c) = m(r, c);
  }
  return out;
}

// The coefficients as OpenCV stores them: radtan 5 when k4..k6 are zero, else 8; fisheye 4.
std::vector<double> OpenCvCoefficients(const Distortion& d) {
  std::vector<double> c = d.coefficients();
  if (d.model() == DistortionModel::kNone) return std::vector<double>(5, 0.0);
  if (d.model() == DistortionModel::kRadialTangential && c[5] == 0 && c[6] == 0 && c[7] == 0) {
    c.resize(5);
  }
  return c;
}

cv::Mat DistortionToCv(const Distortion& d) {
  const std::vector<double> c = OpenCvCoefficients(d);
  return cv::Mat(1, static_cast<int>(c.size()), CV_64F, const_cast<double*>(c.data())).clone();
}

std::vector<double> CvValues(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  return std::vector<double>(d.begin<double>(), d.end<double>());
}

void ExpectSameCamera(const CameraModel& actual, const CameraModel& expected) {
  EXPECT_EQ(actual.intrinsics().width(), expected.intrinsics().width());
  EXPECT_EQ(actual.intrinsics().height(), expected.intrinsics().height());
  const Eigen::Matrix3d a = actual.intrinsics().Matrix();
  const Eigen::Matrix3d e = expected.intrinsics().Matrix();
  for (int i = 0; i < 9; ++i) EXPECT_EQ(a(i / 3, i % 3), e(i / 3, i % 3)) << "K element " << i;
  EXPECT_EQ(ToString(actual.distortion().model()), ToString(expected.distortion().model()));
  EXPECT_EQ(actual.distortion().coefficients(), expected.distortion().coefficients());
}

void ExpectCvMatrixEq(const cv::Mat& m, const Eigen::Matrix3d& expected) {
  ASSERT_EQ(m.rows, 3);
  ASSERT_EQ(m.cols, 3);
  ASSERT_EQ(m.type(), CV_64F);
  for (int i = 0; i < 9; ++i) {
    EXPECT_EQ(m.at<double>(i / 3, i % 3), expected(i / 3, i % 3)) << "element " << i;
  }
}

// Writes one camera with cv::FileStorage, as OpenCV's calibration samples do.
void WriteWithOpenCv(const fs::path& path, const CameraModel& camera, const std::string& name) {
  cv::FileStorage storage(path.string(), cv::FileStorage::WRITE);
  ASSERT_TRUE(storage.isOpened());
  storage.writeComment("written by cv::FileStorage");
  storage << "calibration_time"
          << "Wed 08 Dec 2021 05:13:09 PM MSK";
  storage << "image_width" << camera.intrinsics().width();
  storage << "image_height" << camera.intrinsics().height();
  if (!name.empty()) storage << "camera_name" << name;
  storage << "flags" << 0;
  storage << "fisheye_model" << (camera.distortion().model() == DistortionModel::kFisheye ? 1 : 0);
  storage << "camera_matrix" << ToCv(camera.intrinsics().Matrix());
  storage << "distortion_coefficients" << DistortionToCv(camera.distortion());
  storage << "avg_reprojection_error" << 0.18234905535936044;
  storage << "per_view_reprojection_errors" << cv::Mat((cv::Mat_<float>(1, 3) << 0.1f, 0.2f, 0.3f));
}

TEST_F(CalibrationIoTest, ReadsCamerasWrittenByOpenCvFileStorageBitExactly) {
  std::mt19937 rng(11);
  const std::string name = "left \"cam\" \\ <x> & y'";
  for (const char* extension : {".yml", ".xml"}) {
    for (int i = 0; i < 30; ++i) {
      const DistortionModel model =
          i % 3 == 2 ? DistortionModel::kFisheye : DistortionModel::kRadialTangential;
      const CameraModel camera = RandomCamera(rng, model, i % 3 == 1 ? 8 : 5);
      const fs::path path = Path("camera" + std::to_string(i) + extension);
      WriteWithOpenCv(path, camera, i % 2 == 0 ? name : "");
      SCOPED_TRACE(path.string());
      const CameraCalibration read = ReadCameraCalibration(path);
      ExpectSameCamera(read.model, camera);
      EXPECT_EQ(read.name, i % 2 == 0 ? name : "");
    }
  }
}

TEST_F(CalibrationIoTest, ReadsFloatMatricesAsTheFloatValues) {
  std::mt19937 rng(12);
  const CameraModel camera = RandomCamera(rng, DistortionModel::kRadialTangential);
  for (const char* extension : {".yml", ".xml"}) {
    const fs::path path = Path(std::string("float") + extension);
    cv::Mat K, D;
    ToCv(camera.intrinsics().Matrix()).convertTo(K, CV_32F);
    DistortionToCv(camera.distortion()).convertTo(D, CV_32F);
    {
      cv::FileStorage storage(path.string(), cv::FileStorage::WRITE);
      storage << "image_width" << 640 << "image_height" << 480;
      storage << "camera_matrix" << K << "distortion_coefficients" << D;
    }
    const CameraCalibration read = ReadCameraCalibration(path);
    const Eigen::Matrix3d k = read.model.intrinsics().Matrix();
    for (int i = 0; i < 9; ++i) {
      EXPECT_EQ(k(i / 3, i % 3), static_cast<double>(K.at<float>(i / 3, i % 3)));
    }
    for (int i = 0; i < 5; ++i) {
      EXPECT_EQ(read.model.distortion().coefficients()[static_cast<size_t>(i)],
                static_cast<double>(D.at<float>(0, i)));
    }
  }
}

struct RandomStereo {
  StereoCalibration calibration;
  cv::Mat R, T;
};

RandomStereo MakeStereo(std::mt19937& rng, DistortionModel model) {
  CameraModel left = RandomCamera(rng, model);
  const Intrinsics& li = left.intrinsics();
  CameraModel right_random = RandomCamera(rng, model, 8);
  // Both cameras of a stereo file share one image size.
  const Intrinsics& ri = right_random.intrinsics();
  CameraModel right(Intrinsics(li.width(), li.height(), ri.fx(), ri.fy(), ri.cx(), ri.cy()),
                    right_random.distortion());
  RandomStereo s{StereoCalibration{left, right}, cv::Mat(), cv::Mat()};
  s.calibration.R = RandomRotation(rng);
  s.calibration.T = Eigen::Vector3d(Uniform(rng, -0.2, -0.05), Uniform(rng, -0.01, 0.01),
                                    Uniform(rng, -0.01, 0.01));
  s.R = ToCv(s.calibration.R);
  s.T = (cv::Mat_<double>(3, 1) << s.calibration.T.x(), s.calibration.T.y(), s.calibration.T.z());
  return s;
}

void ExpectSameStereo(const StereoCalibration& actual, const StereoCalibration& expected) {
  {
    SCOPED_TRACE("left");
    ExpectSameCamera(actual.left, expected.left);
  }
  {
    SCOPED_TRACE("right");
    ExpectSameCamera(actual.right, expected.right);
  }
  for (int i = 0; i < 9; ++i) EXPECT_EQ(actual.R(i / 3, i % 3), expected.R(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) EXPECT_EQ(actual.T(i), expected.T(i));
}

TEST_F(CalibrationIoTest, ReadsStereoWrittenByOpenCvInOneOrTwoFiles) {
  std::mt19937 rng(13);
  for (const char* extension : {".yml", ".xml"}) {
    for (int i = 0; i < 6; ++i) {
      const RandomStereo s = MakeStereo(
          rng, i % 2 == 0 ? DistortionModel::kRadialTangential : DistortionModel::kFisheye);
      const StereoCalibration& c = s.calibration;
      const ImageSize size{c.left.intrinsics().width(), c.left.intrinsics().height()};
      const fs::path intrinsics = Path(std::string("intrinsics") + extension);
      const fs::path extrinsics = Path(std::string("extrinsics") + extension);
      const fs::path both = Path(std::string("stereo") + extension);
      const int fisheye = c.left.distortion().model() == DistortionModel::kFisheye ? 1 : 0;
      cv::Mat rectification = cv::Mat::eye(3, 3, CV_64F), projection = cv::Mat::ones(3, 4, CV_64F);
      {
        // OpenCV's stereo_calib sample: intrinsics.yml and extrinsics.yml, no image size.
        cv::FileStorage fi(intrinsics.string(), cv::FileStorage::WRITE);
        if (fisheye == 1) fi << "fisheye_model" << 1;
        fi << "M1" << ToCv(c.left.intrinsics().Matrix()) << "D1"
           << DistortionToCv(c.left.distortion()) << "M2" << ToCv(c.right.intrinsics().Matrix())
           << "D2" << DistortionToCv(c.right.distortion());
        cv::FileStorage fe(extrinsics.string(), cv::FileStorage::WRITE);
        fe << "R" << s.R << "T" << s.T << "R1" << rectification << "R2" << rectification << "P1"
           << projection << "P2" << projection << "Q" << cv::Mat::eye(4, 4, CV_64F);
        cv::FileStorage fb(both.string(), cv::FileStorage::WRITE);
        fb << "image_width" << size.width << "image_height" << size.height;
        fb << "fisheye_model" << fisheye;
        fb << "M1" << ToCv(c.left.intrinsics().Matrix()) << "D1"
           << DistortionToCv(c.left.distortion()) << "M2" << ToCv(c.right.intrinsics().Matrix())
           << "D2" << DistortionToCv(c.right.distortion()) << "R" << s.R << "T" << s.T;
      }
      SCOPED_TRACE(std::string(extension) + " stereo " + std::to_string(i));
      ExpectSameStereo(ReadStereoCalibration(intrinsics, extrinsics, size), c);
      ExpectSameStereo(ReadStereoCalibration(both), c);
    }
  }
}

TEST_F(CalibrationIoTest, OpenCvReadsOurCameraFilesBitExactly) {
  std::mt19937 rng(14);
  const std::string name = "left \"cam\" \\ <x> & y'";
  for (const auto format : {CalibrationFormat::kOpenCvYaml, CalibrationFormat::kOpenCvXml}) {
    for (int i = 0; i < 30; ++i) {
      const DistortionModel model =
          i % 3 == 2 ? DistortionModel::kFisheye : DistortionModel::kRadialTangential;
      const CameraModel camera = RandomCamera(rng, model, i % 3 == 1 ? 8 : 5, /*skew=*/true);
      const fs::path path = Path("ours" + std::to_string(i) +
                                 (format == CalibrationFormat::kOpenCvXml ? ".xml" : ".yml"));
      WriteCameraCalibration({camera, name}, path, format);
      SCOPED_TRACE(path.string());
      cv::FileStorage storage(path.string(), cv::FileStorage::READ);
      ASSERT_TRUE(storage.isOpened());
      EXPECT_EQ(static_cast<int>(storage["image_width"]), camera.intrinsics().width());
      EXPECT_EQ(static_cast<int>(storage["image_height"]), camera.intrinsics().height());
      EXPECT_EQ(static_cast<std::string>(storage["camera_name"]), name);
      EXPECT_EQ(static_cast<int>(storage["fisheye_model"]),
                model == DistortionModel::kFisheye ? 1 : 0);
      cv::Mat K, D;
      storage["camera_matrix"] >> K;
      storage["distortion_coefficients"] >> D;
      ExpectCvMatrixEq(K, camera.intrinsics().Matrix());
      EXPECT_EQ(D.type(), CV_64F);
      EXPECT_EQ(CvValues(D), OpenCvCoefficients(camera.distortion()));
      // And our reader reads it back identically.
      const CameraCalibration read = ReadCameraCalibration(path);
      ExpectSameCamera(read.model, camera);
      EXPECT_EQ(read.name, name);
    }
  }
}

TEST_F(CalibrationIoTest, OpenCvReadsOurStereoFilesBitExactly) {
  std::mt19937 rng(15);
  for (const auto format : {CalibrationFormat::kOpenCvYaml, CalibrationFormat::kOpenCvXml}) {
    for (int i = 0; i < 6; ++i) {
      const RandomStereo s = MakeStereo(
          rng, i % 2 == 0 ? DistortionModel::kRadialTangential : DistortionModel::kFisheye);
      const StereoCalibration& c = s.calibration;
      const fs::path path =
          Path(std::string("stereo") + (format == CalibrationFormat::kOpenCvXml ? ".xml" : ".yml"));
      WriteStereoCalibration(c, path, format);
      SCOPED_TRACE(path.string() + " " + std::to_string(i));
      cv::FileStorage storage(path.string(), cv::FileStorage::READ);
      ASSERT_TRUE(storage.isOpened());
      EXPECT_EQ(static_cast<int>(storage["image_width"]), c.left.intrinsics().width());
      EXPECT_EQ(static_cast<int>(storage["image_height"]), c.left.intrinsics().height());
      cv::Mat M1, D1, M2, D2, R, T;
      storage["M1"] >> M1;
      storage["D1"] >> D1;
      storage["M2"] >> M2;
      storage["D2"] >> D2;
      storage["R"] >> R;
      storage["T"] >> T;
      ExpectCvMatrixEq(M1, c.left.intrinsics().Matrix());
      ExpectCvMatrixEq(M2, c.right.intrinsics().Matrix());
      ExpectCvMatrixEq(R, c.R);
      EXPECT_EQ(CvValues(D1), OpenCvCoefficients(c.left.distortion()));
      EXPECT_EQ(CvValues(D2), OpenCvCoefficients(c.right.distortion()));
      EXPECT_EQ(CvValues(T), std::vector<double>({c.T.x(), c.T.y(), c.T.z()}));
      ExpectSameStereo(ReadStereoCalibration(path), c);
    }
  }
}

TEST_F(CalibrationIoTest, RosFilesRoundTripAndParseAsCameraCalibrationParsersReadsThem) {
  std::mt19937 rng(16);
  const struct {
    DistortionModel model;
    int count;
    const char* ros_name;
  } kCases[] = {{DistortionModel::kRadialTangential, 5, "plumb_bob"},
                {DistortionModel::kRadialTangential, 8, "rational_polynomial"},
                {DistortionModel::kFisheye, 4, "equidistant"}};
  int index = 0;
  for (const auto& c : kCases) {
    for (int i = 0; i < 10; ++i, ++index) {
      const CameraModel camera = RandomCamera(rng, c.model, c.count, /*skew=*/true);
      const fs::path path = Path("ros" + std::to_string(index) + ".yaml");
      WriteCameraCalibration({camera, "narrow_stereo/left"}, path, CalibrationFormat::kRosYaml);
      SCOPED_TRACE(path.string());
      EXPECT_EQ(DetectCalibrationFormat(path), CalibrationFormat::kRosYaml);
      const CameraCalibration read = ReadCameraCalibration(path);
      ExpectSameCamera(read.model, camera);
      EXPECT_EQ(read.name, "narrow_stereo/left");
      // camera_calibration_parsers reads these keys with yaml-cpp.
      const YAML::Node ros = YAML::LoadFile(path.string());
      EXPECT_EQ(ros["image_width"].as<int>(), camera.intrinsics().width());
      EXPECT_EQ(ros["image_height"].as<int>(), camera.intrinsics().height());
      EXPECT_EQ(ros["camera_name"].as<std::string>(), "narrow_stereo/left");
      EXPECT_EQ(ros["distortion_model"].as<std::string>(), c.ros_name);
      EXPECT_EQ(ros["distortion_coefficients"]["cols"].as<int>(), c.count);
      EXPECT_EQ(ros["distortion_coefficients"]["data"].as<std::vector<double>>(),
                OpenCvCoefficients(camera.distortion()));
      const auto K = ros["camera_matrix"]["data"].as<std::vector<double>>();
      const auto R = ros["rectification_matrix"]["data"].as<std::vector<double>>();
      const auto P = ros["projection_matrix"]["data"].as<std::vector<double>>();
      ASSERT_EQ(K.size(), 9u);
      ASSERT_EQ(R.size(), 9u);
      ASSERT_EQ(P.size(), 12u);
      const Eigen::Matrix3d k = camera.intrinsics().Matrix();
      for (int j = 0; j < 9; ++j) {
        EXPECT_EQ(K[static_cast<size_t>(j)], k(j / 3, j % 3));
        EXPECT_EQ(R[static_cast<size_t>(j)], j % 4 == 0 ? 1.0 : 0.0);
        EXPECT_EQ(P[static_cast<size_t>(j / 3 * 4 + j % 3)], k(j / 3, j % 3));
      }
      EXPECT_EQ(P[3], 0.0);
      EXPECT_EQ(P[7], 0.0);
      EXPECT_EQ(P[11], 0.0);
    }
  }
}

// The layout camera_calibration_parsers' writeCalibrationYml produces.
const char kRosFile[] = R"(image_width: 640
image_height: 480
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [430.2153, 0, 306.6968, 0, 430.5318, 227.2202, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.337586, 0.111049, -0.000312, 0.000289, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [0.999965, 0.00156, -0.008193, -0.001557, 0.999998, 0.000315, 0.008194, -0.000302, 0.999966]
projection_matrix:
  rows: 3
  cols: 4
  data: [295.5373, 0, 285.5572, 0, 0, 295.5373, 223.2904, 0, 0, 0, 1, 0]
)";

TEST_F(CalibrationIoTest, ReadsRosFileAsCameraCalibrationParsersWritesIt) {
  const fs::path path = WriteText("left.yaml", kRosFile);
  EXPECT_EQ(DetectCalibrationFormat(path), CalibrationFormat::kRosYaml);
  const CameraCalibration read = ReadCameraCalibration(path);
  EXPECT_EQ(read.name, "narrow_stereo");
  const Intrinsics& k = read.model.intrinsics();
  EXPECT_EQ(k.width(), 640);
  EXPECT_EQ(k.height(), 480);
  EXPECT_EQ(k.fx(), 430.2153);
  EXPECT_EQ(k.fy(), 430.5318);
  EXPECT_EQ(k.cx(), 306.6968);
  EXPECT_EQ(k.cy(), 227.2202);
  EXPECT_EQ(k.skew(), 0.0);
  EXPECT_EQ(read.model.distortion().model(), DistortionModel::kRadialTangential);
  EXPECT_EQ(read.model.distortion().coefficients(),
            std::vector<double>({-0.337586, 0.111049, -0.000312, 0.000289, 0, 0, 0, 0}));
}

TEST_F(CalibrationIoTest, ReadsRosNoneModelAsNoDistortion) {
  std::string text = kRosFile;
  text = Replace(Replace(text, "plumb_bob", "none"), "-0.337586, 0.111049, -0.000312, 0.000289, 0",
                 "0, 0, 0, 0, 0");
  const CameraCalibration read = ReadCameraCalibration(WriteText("none.yaml", text));
  EXPECT_EQ(read.model.distortion().model(), DistortionModel::kNone);
}

TEST_F(CalibrationIoTest, WritesRadtanWithFiveCoefficientsUnlessRational) {
  std::mt19937 rng(17);
  for (const int count : {4, 5, 8}) {
    const CameraModel camera = RandomCamera(rng, DistortionModel::kRadialTangential, count);
    const fs::path path = Path("count" + std::to_string(count) + ".yml");
    WriteCameraCalibration({camera, ""}, path, CalibrationFormat::kOpenCvYaml);
    cv::FileStorage storage(path.string(), cv::FileStorage::READ);
    cv::Mat D;
    storage["distortion_coefficients"] >> D;
    EXPECT_EQ(D.total(), count == 8 ? 8u : 5u) << count << " coefficients";
    EXPECT_TRUE(storage["camera_name"].empty()) << "no name, no camera_name key";
  }
}

TEST_F(CalibrationIoTest, WritesNoDistortionAsFiveZeroCoefficients) {
  std::mt19937 rng(18);
  const CameraModel camera = RandomCamera(rng, DistortionModel::kNone);
  for (const auto format : {CalibrationFormat::kOpenCvYaml, CalibrationFormat::kOpenCvXml,
                            CalibrationFormat::kRosYaml}) {
    const fs::path path = Path(format == CalibrationFormat::kOpenCvXml ? "none.xml" : "none.yml");
    WriteCameraCalibration({camera, ""}, path, format);
    const CameraCalibration read = ReadCameraCalibration(path);
    EXPECT_EQ(read.model.intrinsics(), camera.intrinsics());
    EXPECT_EQ(read.model.distortion().model(), DistortionModel::kRadialTangential);
    EXPECT_TRUE(read.model.distortion().IsIdentity());
  }
}

TEST_F(CalibrationIoTest, ImageSizeComesFromTheFileElseTheArgument) {
  std::mt19937 rng(19);
  const CameraModel camera = RandomCamera(rng, DistortionModel::kRadialTangential);
  const fs::path path = Path("nosize.yml");
  {
    cv::FileStorage storage(path.string(), cv::FileStorage::WRITE);
    storage << "camera_matrix" << ToCv(camera.intrinsics().Matrix());
    storage << "distortion_coefficients" << DistortionToCv(camera.distortion());
  }
  const CameraCalibration read = ReadCameraCalibration(path, ImageSize{800, 600});
  EXPECT_EQ(read.model.intrinsics().width(), 800);
  EXPECT_EQ(read.model.intrinsics().height(), 600);
  EXPECT_THROW(ReadCameraCalibration(path, ImageSize{0, 600}), InvalidArgument);

  const fs::path sized = Path("sized.yml");
  WriteCameraCalibration({camera, ""}, sized, CalibrationFormat::kOpenCvYaml);
  EXPECT_EQ(ReadCameraCalibration(sized, ImageSize{800, 600}).model.intrinsics(),
            camera.intrinsics())
      << "the file's size wins over the argument";
}

TEST_F(CalibrationIoTest, DetectsFormatByExtensionAndContent) {
  std::mt19937 rng(20);
  const CameraModel camera = RandomCamera(rng, DistortionModel::kRadialTangential);
  WriteCameraCalibration({camera, ""}, Path("a.yml"), CalibrationFormat::kOpenCvYaml);
  WriteCameraCalibration({camera, ""}, Path("a.xml"), CalibrationFormat::kOpenCvXml);
  WriteCameraCalibration({camera, ""}, Path("a.yaml"), CalibrationFormat::kRosYaml);
  WriteCameraCalibration({camera, ""}, Path("xml.txt"), CalibrationFormat::kOpenCvXml);
  EXPECT_EQ(DetectCalibrationFormat(Path("a.yml")), CalibrationFormat::kOpenCvYaml);
  EXPECT_EQ(DetectCalibrationFormat(Path("a.xml")), CalibrationFormat::kOpenCvXml);
  EXPECT_EQ(DetectCalibrationFormat(Path("a.yaml")), CalibrationFormat::kRosYaml);
  EXPECT_EQ(DetectCalibrationFormat(Path("xml.txt")), CalibrationFormat::kOpenCvXml);
  ExpectSameCamera(ReadCameraCalibration(Path("xml.txt")).model, camera);
  EXPECT_THROW(DetectCalibrationFormat(Path("missing.yml")), FileError);
}

// ---------------------------------------------------------------------------------------
// Files OpenCV ships (Debian package opencv-doc).

cv::Mat CvRead(const fs::path& path, const char* key) {
  cv::FileStorage storage(path.string(), cv::FileStorage::READ);
  cv::Mat m;
  storage[key] >> m;
  return m;
}

void ExpectMatchesOpenCv(const CameraModel& model, const fs::path& path, const char* k_key,
                         const char* d_key) {
  const cv::Mat K = CvRead(path, k_key);
  ExpectCvMatrixEq(K, model.intrinsics().Matrix());
  std::vector<double> d = CvValues(CvRead(path, d_key));
  d.resize(8, 0.0);
  EXPECT_EQ(model.distortion().coefficients(), d);
}

TEST_F(CalibrationIoTest, ReadsOpenCvSampleCalibrationFiles) {
  // Written by OpenCV's calibration sample: image size, camera_matrix, 5x1 coefficients.
  const fs::path left = kOpenCvExamples / "data/left_intrinsics.yml";
  // Written by OpenCV's aruco/charuco calibration tutorials.
  const fs::path charuco = kOpenCvExamples / "aruco/tutorial_camera_charuco.yml";
  const fs::path params = kOpenCvExamples / "aruco/tutorial_camera_params.yml";
  for (const fs::path& path : {left, charuco, params}) {
    ASSERT_TRUE(fs::exists(path)) << path << " is installed by Debian's opencv-doc package";
  }
  const CameraCalibration l = ReadCameraCalibration(left);
  EXPECT_EQ(l.model.intrinsics().width(), 640);
  EXPECT_EQ(l.model.intrinsics().height(), 480);
  EXPECT_EQ(l.model.intrinsics().fx(), 5.3591573396163199e+02);
  ExpectMatchesOpenCv(l.model, left, "camera_matrix", "distortion_coefficients");

  const CameraCalibration c = ReadCameraCalibration(charuco);
  EXPECT_EQ(c.model.intrinsics().width(), 640);
  ExpectMatchesOpenCv(c.model, charuco, "camera_matrix", "distortion_coefficients");

  // No image size in this one: it must be given.
  try {
    ReadCameraCalibration(params);
    ADD_FAILURE() << "expected a FileError naming image_width";
  } catch (const FileError& e) {
    EXPECT_EQ(e.key(), "image_width");
  }
  const CameraCalibration p = ReadCameraCalibration(params, ImageSize{640, 480});
  EXPECT_EQ(p.model.intrinsics().fx(), 628.158);
  ExpectMatchesOpenCv(p.model, params, "camera_matrix", "distortion_coefficients");
}

TEST_F(CalibrationIoTest, ReadsOpenCvStereoSampleIntrinsics) {
  // stereo_calib's intrinsics.yml (M1 D1 M2 D2, no image size); the sample ships no
  // extrinsics.yml, so one is written here as stereo_calib writes it.
  const fs::path intrinsics = kOpenCvExamples / "data/intrinsics.yml";
  ASSERT_TRUE(fs::exists(intrinsics)) << intrinsics << " is installed by opencv-doc";
  try {
    ReadStereoCalibration(intrinsics, std::nullopt, ImageSize{640, 480});
    ADD_FAILURE() << "expected a FileError naming R";
  } catch (const FileError& e) {
    EXPECT_EQ(e.key(), "R");
    EXPECT_NE(std::string(e.what()).find(intrinsics.string()), std::string::npos) << e.what();
  }
  std::mt19937 rng(21);
  const Eigen::Matrix3d R = RandomRotation(rng);
  const cv::Mat T = (cv::Mat_<double>(3, 1) << -3.33, 0.01, -0.02);
  const fs::path extrinsics = Path("extrinsics.yml");
  {
    cv::FileStorage storage(extrinsics.string(), cv::FileStorage::WRITE);
    storage << "R" << ToCv(R) << "T" << T << "R1" << cv::Mat::eye(3, 3, CV_64F);
  }
  const StereoCalibration s = ReadStereoCalibration(intrinsics, extrinsics, ImageSize{640, 480});
  ExpectMatchesOpenCv(s.left, intrinsics, "M1", "D1");
  ExpectMatchesOpenCv(s.right, intrinsics, "M2", "D2");
  EXPECT_EQ(s.left.intrinsics().cx(), 3.3568643204394891e+02);
  EXPECT_EQ(s.right.intrinsics().cy(), 2.4205324573376600e+02);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(s.R(i / 3, i % 3), R(i / 3, i % 3));
  EXPECT_EQ(s.T, Eigen::Vector3d(-3.33, 0.01, -0.02));
}

// ---------------------------------------------------------------------------------------
// Bad files: each gives a FileError naming the file, the line and the key.

// OpenCV YAML with its line numbers: 3 image_width, 5 camera_matrix, 8 its dt, 9 its data,
// 10 distortion_coefficients, 14 its data.
const char kGoodYaml[] = R"(%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ 0.1, -0.2, 0.001, 0.002, 0.05 ]
)";

// OpenCV XML: 4 image_width, 6 camera_matrix, 7 rows, 9 dt, 11-13 its data rows,
// 14 distortion_coefficients.
const char kGoodXml[] = R"(<?xml version="1.0"?>
<opencv_storage>
<!-- written by hand -->
<image_width>640</image_width>
<image_height>480</image_height>
<camera_matrix type_id="opencv-matrix">
  <rows>3</rows>
  <cols>3</cols>
  <dt>d</dt>
  <data>
    500. 0. 320.
    0. 500. 240.
    0. 0. 1.</data></camera_matrix>
<distortion_coefficients type_id="opencv-matrix">
  <rows>1</rows>
  <cols>5</cols>
  <dt>d</dt>
  <data>
    0.1 -0.2 0.001 0.002 0.05</data></distortion_coefficients>
</opencv_storage>
)";

// Stereo YAML: 3 M1, 13 M2, 23 R, 28 T.
const char kGoodStereo[] = R"(%YAML:1.0
---
M1: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]
D1: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ 0.1, -0.2, 0., 0., 0. ]
M2: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 501., 0., 321., 0., 501., 241., 0., 0., 1. ]
D2: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ 0.1, -0.2, 0., 0., 0. ]
R: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]
T: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ -0.06, 0., 0. ]
)";

TEST_F(CalibrationIoTest, GoodTemplatesOfTheBadFileCasesRead) {
  EXPECT_NO_THROW(ReadCameraCalibration(WriteText("good.yml", kGoodYaml)));
  EXPECT_NO_THROW(ReadCameraCalibration(WriteText("good.xml", kGoodXml)));
  EXPECT_NO_THROW(ReadCameraCalibration(WriteText("good.yaml", kRosFile)));
  EXPECT_NO_THROW(ReadStereoCalibration(WriteText("good_stereo.yml", kGoodStereo), std::nullopt,
                                        ImageSize{640, 480}));
}

enum class Reader { kCamera, kStereo };

struct BadFile {
  std::string name;       // test name
  std::string file_name;  // with the extension that picks the parser
  std::string content;
  std::string key;  // FileError::key()
  int line;         // FileError::line(); -1: any line > 0
  std::vector<std::string> message_parts;
  Reader reader = Reader::kCamera;
};

const char kKRows[] =
    "rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 320., 0., 500., 240., 0., 0., 1. ]";

std::vector<BadFile> BadFiles() {
  const std::string y = kGoodYaml;
  const std::string x = kGoodXml;
  const std::string r = kRosFile;
  const std::string s = kGoodStereo;
  return {
      // Not a calibration file at all.
      {"EmptyYaml", "a.yml", "", "", 0, {"empty"}},
      {"NotAYamlMap", "a.yml", "just some words\n", "", 1, {"expected YAML keys"}},
      {"BadYamlSyntax", "a.yml", Replace(y, "1. ]", "1."), "", -1, {"not valid YAML"}},
      {"BinaryContent", "a.yml", std::string("\x01\x02\0\x03", 4), "", 0, {"binary"}},
      {"NotXml", "a.xml", "hello\n", "", 1, {"not an XML file"}},
      {"XmlWrongRoot",
       "a.xml",
       Replace(Replace(x, "<opencv_storage>", "<storage>"), "</opencv_storage>", "</storage>"),
       "opencv_storage",
       2,
       {"<storage>"}},
      {"XmlNotClosed",
       "a.xml",
       Replace(x, "</opencv_storage>", ""),
       "opencv_storage",
       -1,
       {"opened at line 2 is not closed"}},
      {"XmlMismatchedTag",
       "a.xml",
       Replace(x, "</rows>", "</cols>"),
       "rows",
       7,
       {"expected </rows>", "</cols>"}},
      {"XmlUnknownEntity", "a.xml", Replace(x, ">640<", ">&foo;640<"), "", 4, {"&foo;"}},
      {"XmlUnterminatedComment", "a.xml", Replace(x, "hand -->", "hand"), "", 3, {"comment"}},
      // Missing keys.
      {"MissingCameraMatrix",
       "a.yml",
       Replace(y, "camera_matrix:", "camera_matrx:"),
       "camera_matrix",
       0,
       {"missing key"}},
      {"MissingDistortion",
       "a.yml",
       Replace(y, "distortion_coefficients:", "distortion:"),
       "distortion_coefficients",
       0,
       {"missing key"}},
      {"MissingImageSize",
       "a.yml",
       Replace(Replace(y, "image_width: 640\n", ""), "image_height: 480\n", ""),
       "image_width",
       0,
       {"missing key", "no size was given"}},
      {"MissingImageWidth",
       "a.yml",
       Replace(y, "image_width: 640\n", ""),
       "image_width",
       0,
       {"image_height (line 3)"}},
      {"MissingMatrixRows",
       "a.yml",
       Replace(y, "rows: 3\n   ", ""),
       "camera_matrix.rows",
       5,
       {"missing key"}},
      {"MissingMatrixData",
       "a.xml",
       Replace(x, "<data>\n    500. 0. 320.\n    0. 500. 240.\n    0. 0. 1.</data>", ""),
       "camera_matrix.data",
       6,
       {"missing key"}},
      {"XmlMissingImageWidth",
       "a.xml",
       Replace(x, "<image_width>640</image_width>\n", ""),
       "image_width",
       0,
       {"missing key"}},
      // Matrices.
      {"CameraMatrix2x3",
       "a.yml",
       Replace(y, kKRows,
               "rows: 2\n   cols: 3\n   dt: d\n   data: [ 500., 0., 320., 0., 500., 240. ]"),
       "camera_matrix",
       5,
       {"3x3", "2x3"}},
      {"WrongDt", "a.yml", Replace(y, "dt: d", "dt: i"), "camera_matrix.dt", 8, {"'i'"}},
      {"NonNumericData",
       "a.yml",
       Replace(y, "500., 0., 320.", "500., abc, 320."),
       "camera_matrix.data[1]",
       9,
       {"'abc'"}},
      {"NonFiniteData",
       "a.yml",
       Replace(y, "500., 0., 320.", "500., .Nan, 320."),
       "camera_matrix.data[1]",
       9,
       {"finite", "'.Nan'"}},
      {"DataLengthIsNotRowsTimesCols",
       "a.yml",
       Replace(y, "0., 0., 1. ]", "0., 0. ]"),
       "camera_matrix.data",
       9,
       {"8 values", "3x3 = 9"}},
      {"NotAMatrix",
       "a.yml",
       Replace(y, "camera_matrix: !!opencv-matrix\n   " + std::string(kKRows), "camera_matrix: 5"),
       "camera_matrix",
       5,
       {"expected a matrix"}},
      {"XmlCameraMatrix2x3",
       "a.xml",
       Replace(Replace(x, "<rows>3</rows>", "<rows>2</rows>"), "\n    0. 0. 1.</data>", "</data>"),
       "camera_matrix",
       6,
       {"2x3"}},
      {"XmlWrongDt",
       "a.xml",
       Replace(x, "<dt>d</dt>", "<dt>u</dt>"),
       "camera_matrix.dt",
       9,
       {"'u'"}},
      {"XmlNonNumericData",
       "a.xml",
       Replace(x, "0. 500. 240.", "0. x5 240."),
       "camera_matrix.data[4]",
       12,
       {"'x5'"}},
      {"XmlDataLengthIsNotRowsTimesCols",
       "a.xml",
       Replace(x, "0. 0. 1.</data>", "0. 0.</data>"),
       "camera_matrix.data",
       11,
       {"8 values"}},
      // Values.
      {"InvalidIntrinsics",
       "a.yml",
       Replace(y, "[ 500., 0., 320.", "[ -500., 0., 320."),
       "camera_matrix",
       5,
       {"invalid camera matrix", "fx"}},
      {"NotUpperTriangular",
       "a.yml",
       Replace(y, "0., 0., 1. ]", "0., 0., 2. ]"),
       "camera_matrix",
       5,
       {"invalid camera matrix"}},
      {"NegativeImageWidth",
       "a.yml",
       Replace(y, "image_width: 640", "image_width: -640"),
       "image_width",
       3,
       {"-640"}},
      {"NonIntegerImageWidth",
       "a.yml",
       Replace(y, "image_width: 640", "image_width: 640.5"),
       "image_width",
       3,
       {"'640.5'"}},
      {"SixDistortionCoefficients",
       "a.yml",
       Replace(y, "cols: 5\n   dt: d\n   data: [ 0.1, -0.2, 0.001, 0.002, 0.05 ]",
               "cols: 6\n   dt: d\n   data: [ 0.1, -0.2, 0.001, 0.002, 0.05, 0.1 ]"),
       "distortion_coefficients",
       10,
       {"invalid distortion coefficients"}},
      {"DistortionIsNotAVector",
       "a.yml",
       Replace(Replace(y, "rows: 1\n   cols: 5", "rows: 2\n   cols: 3"), "0.05 ]", "0.05, 0.1 ]"),
       "distortion_coefficients",
       10,
       {"2x3"}},
      {"FisheyeWithFiveCoefficients",
       "a.yml",
       y + "fisheye_model: 1\n",
       "distortion_coefficients",
       10,
       {"invalid distortion coefficients"}},
      {"FisheyeModelNotZeroOrOne",
       "a.yml",
       y + "fisheye_model: 2\n",
       "fisheye_model",
       15,
       {"expected 0"}},
      {"DuplicateKey",
       "a.yml",
       y + "image_width: 800\n",
       "image_width",
       15,
       {"duplicate", "line 3"}},
      // ROS camera_info: 4 camera_matrix, 7 its data, 8 distortion_model,
      // 9 distortion_coefficients.
      {"RosUnknownDistortionModel",
       "a.yaml",
       Replace(r, "plumb_bob", "fish"),
       "distortion_model",
       8,
       {"'fish'", "plumb_bob"}},
      {"RosPlumbBobWithEight",
       "a.yaml",
       Replace(Replace(r, "cols: 5", "cols: 8"), "0.000289, 0]", "0.000289, 0, 0, 0, 0]"),
       "distortion_coefficients",
       9,
       {"plumb_bob", "8"}},
      {"RosEquidistantWithFive",
       "a.yaml",
       Replace(r, "plumb_bob", "equidistant"),
       "distortion_coefficients",
       9,
       {"invalid distortion coefficients"}},
      {"RosCameraMatrix2x3",
       "a.yaml",
       Replace(Replace(r, "rows: 3\n  cols: 3\n  data: [430", "rows: 2\n  cols: 3\n  data: [430"),
               ", 0, 0, 1]\ndistortion_model", "]\ndistortion_model"),
       "camera_matrix",
       4,
       {"2x3"}},
      {"RosNonNumeric",
       "a.yaml",
       Replace(r, "430.5318", "43o.5318"),
       "camera_matrix.data[4]",
       7,
       {"'43o.5318'"}},
      {"RosMissingCameraMatrix",
       "a.yaml",
       Replace(r, "camera_matrix:", "camera_matri:"),
       "camera_matrix",
       0,
       {"missing key"}},
      // Stereo: 3 M1, 13 M2, 23 R, 28 T.
      {"StereoMissingR",
       "a.yml",
       Replace(s, "R: !!", "Rot: !!"),
       "R",
       0,
       {"missing key"},
       Reader::kStereo},
      {"StereoRNotARotation",
       "a.yml",
       Replace(s, "[ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]",
               "[ 1., 0., 0., 0., 2., 0., 0., 0., 1. ]"),
       "R",
       23,
       {"rotation"},
       Reader::kStereo},
      {"StereoTNotAThreeVector",
       "a.yml",
       Replace(Replace(s, "rows: 3\n   cols: 1", "rows: 2\n   cols: 1"), "-0.06, 0., 0.",
               "-0.06, 0."),
       "T",
       28,
       {"2x1"},
       Reader::kStereo},
      {"StereoM2Invalid",
       "a.yml",
       Replace(s, "501., 0., 321., 0., 501.", "501., 0., 321., 0., 0."),
       "M2",
       13,
       {"invalid camera matrix", "fy"},
       Reader::kStereo},
      {"StereoMissingD2",
       "a.yml",
       Replace(s, "D2:", "D3:"),
       "D2",
       0,
       {"missing key"},
       Reader::kStereo},
  };
}

// Test names instead of bytes in gtest's output.
void PrintTo(const BadFile& bad, std::ostream* out) { *out << bad.name; }

class BadFileTest : public CalibrationIoTest, public ::testing::WithParamInterface<BadFile> {};

TEST_P(BadFileTest, ThrowsFileErrorNamingFileLineAndKey) {
  const BadFile& bad = GetParam();
  const fs::path path = WriteText(bad.file_name, bad.content);
  try {
    if (bad.reader == Reader::kCamera) {
      ReadCameraCalibration(path);
    } else {
      ReadStereoCalibration(path, std::nullopt, ImageSize{640, 480});
    }
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.file(), path.string());
    EXPECT_EQ(e.key(), bad.key) << message;
    if (bad.line >= 0) {
      EXPECT_EQ(e.line(), bad.line) << message;
    } else {
      EXPECT_GT(e.line(), 0) << message;
    }
    std::vector<std::string> parts = bad.message_parts;
    parts.push_back(e.line() > 0 ? path.string() + ":" + std::to_string(e.line()) + ": "
                                 : path.string() + ": ");
    if (!bad.key.empty()) parts.push_back(bad.key + ": ");
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(CalibrationIo, BadFileTest, ::testing::ValuesIn(BadFiles()),
                         [](const ::testing::TestParamInfo<BadFile>& info) {
                           return info.param.name;
                         });

TEST_F(CalibrationIoTest, MissingFileAndDirectoryThrowFileError) {
  for (const fs::path& path : {Path("missing.yml"), dir_}) {
    try {
      ReadCameraCalibration(path);
      ADD_FAILURE() << "no FileError for " << path;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      EXPECT_EQ(e.line(), 0);
    }
  }
}

TEST_F(CalibrationIoTest, ADeviceIsRefusedBeforeReading) {
  // Issue 18: /dev/zero never ends; reading it whole took all memory.
  try {
    ReadCameraCalibration("/dev/zero");
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_EQ(e.file(), "/dev/zero");
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
}

TEST_F(CalibrationIoTest, StereoImageSizeMissingEverywhereNamesImageWidth) {
  const fs::path path = WriteText("stereo.yml", kGoodStereo);
  try {
    ReadStereoCalibration(path);
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_EQ(e.key(), "image_width");
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------
// One camera of a stereo file (ReadStereoCameraCalibration).

TEST_F(CalibrationIoTest, ReadsEachCameraOfStereoSampleIntrinsicsWithoutExtrinsics) {
  const fs::path intrinsics = kOpenCvExamples / "data/intrinsics.yml";
  ASSERT_TRUE(fs::exists(intrinsics)) << intrinsics << " is installed by opencv-doc";
  const CameraCalibration left = ReadStereoCameraCalibration(intrinsics, 1, ImageSize{640, 480});
  const CameraCalibration right = ReadStereoCameraCalibration(intrinsics, 2, ImageSize{640, 480});
  ExpectMatchesOpenCv(left.model, intrinsics, "M1", "D1");
  ExpectMatchesOpenCv(right.model, intrinsics, "M2", "D2");
  EXPECT_EQ(left.model.intrinsics().width(), 640);
  EXPECT_EQ(right.model.intrinsics().height(), 480);
  EXPECT_EQ(left.model.distortion().model(), DistortionModel::kRadialTangential);
  EXPECT_TRUE(left.name.empty());
}

TEST_F(CalibrationIoTest, ReadsTheImageSizeAloneWhereTheFileHasOne) {
  const std::optional<ImageSize> left =
      ReadCalibrationImageSize(kOpenCvExamples / "data/left_intrinsics.yml");
  ASSERT_TRUE(left.has_value());
  EXPECT_EQ(left->width, 640);
  EXPECT_EQ(left->height, 480);
  EXPECT_FALSE(ReadCalibrationImageSize(kOpenCvExamples / "data/intrinsics.yml").has_value());
  const std::optional<ImageSize> xml = ReadCalibrationImageSize(WriteText("good.xml", kGoodXml));
  ASSERT_TRUE(xml.has_value());
  EXPECT_EQ(xml->width, 640);
  try {
    ReadCalibrationImageSize(WriteText("half.yml", Replace(kGoodYaml, "image_height: 480\n", "")));
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_EQ(e.key(), "image_height");
  }
  EXPECT_THROW(ReadCalibrationImageSize(Path("missing.yml")), FileError);
}

TEST_F(CalibrationIoTest, StereoCameraMatchesTheFullStereoReader) {
  // With R and T present, camera 1 and 2 are exactly ReadStereoCalibration's left and right.
  const fs::path path = WriteText("stereo.yml", kGoodStereo);
  const StereoCalibration stereo = ReadStereoCalibration(path, std::nullopt, ImageSize{320, 200});
  ExpectSameCamera(ReadStereoCameraCalibration(path, 1, ImageSize{320, 200}).model, stereo.left);
  ExpectSameCamera(ReadStereoCameraCalibration(path, 2, ImageSize{320, 200}).model, stereo.right);
}

TEST_F(CalibrationIoTest, StereoCameraErrorsNameFileLineAndKey) {
  // Line 13 of kGoodStereo is M2; its data is on line 17.
  const fs::path bad_data =
      WriteText("bad.yml", Replace(kGoodStereo, "501., 0., 321.", "501., x, 321."));
  try {
    ReadStereoCameraCalibration(bad_data, 2, ImageSize{640, 480});
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_EQ(e.key(), "M2.data[1]");
    EXPECT_EQ(e.line(), 17);
    EXPECT_NE(std::string(e.what()).find(bad_data.string() + ":17:"), std::string::npos)
        << e.what();
  }
  // Camera 1 of the same file is fine: only the keys read are checked.
  EXPECT_NO_THROW(ReadStereoCameraCalibration(bad_data, 1, ImageSize{640, 480}));

  const fs::path no_d2 = WriteText("no_d2.yml", Replace(kGoodStereo, "D2:", "D3:"));
  try {
    ReadStereoCameraCalibration(no_d2, 2, ImageSize{640, 480});
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_EQ(e.key(), "D2");
    EXPECT_NE(std::string(e.what()).find("missing key"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(no_d2.string()), std::string::npos) << e.what();
  }

  // A single-camera file: the message says so.
  const fs::path mono = WriteText("mono.yml", kGoodYaml);
  try {
    ReadStereoCameraCalibration(mono, 1);
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_EQ(e.key(), "M1");
    EXPECT_NE(std::string(e.what()).find("camera_matrix"), std::string::npos) << e.what();
  }

  // No image size anywhere.
  try {
    ReadStereoCameraCalibration(WriteText("nosize.yml", kGoodStereo), 1);
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& e) {
    EXPECT_EQ(e.key(), "image_width");
  }

  for (int index : {0, 3, -1}) {
    try {
      ReadStereoCameraCalibration(mono, index);
      ADD_FAILURE() << "no InvalidArgument for index " << index;
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("got " + std::to_string(index)), std::string::npos)
          << e.what();
    }
  }
}

// ---------------------------------------------------------------------------------------
// Writing.

TEST_F(CalibrationIoTest, WritingIntoAMissingDirectoryThrowsAndLeavesNothing) {
  std::mt19937 rng(22);
  const CameraModel camera = RandomCamera(rng, DistortionModel::kRadialTangential);
  const fs::path missing = Path("no_such_dir");
  const fs::path path = missing / "camera.yml";
  for (const auto format : {CalibrationFormat::kOpenCvYaml, CalibrationFormat::kOpenCvXml,
                            CalibrationFormat::kRosYaml}) {
    try {
      WriteCameraCalibration({camera, ""}, path, format);
      ADD_FAILURE() << "no FileError";
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(missing));
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(CalibrationIoTest, FailedReplaceKeepsNoTemporaryFile) {
  std::mt19937 rng(23);
  const CameraModel camera = RandomCamera(rng, DistortionModel::kRadialTangential);
  // A non-empty directory where the file should go: rename(2) fails after the write.
  const fs::path blocked = Path("blocked.yml");
  fs::create_directories(blocked / "inside");
  EXPECT_THROW(WriteCameraCalibration({camera, ""}, blocked, CalibrationFormat::kOpenCvYaml),
               FileError);
  std::vector<fs::path> entries;
  for (const auto& entry : fs::directory_iterator(dir_)) entries.push_back(entry.path());
  EXPECT_EQ(entries, std::vector<fs::path>({blocked}));
}

TEST_F(CalibrationIoTest, WriteReplacesAnExistingFile) {
  std::mt19937 rng(24);
  const CameraModel first = RandomCamera(rng, DistortionModel::kRadialTangential);
  const CameraModel second = RandomCamera(rng, DistortionModel::kFisheye);
  const fs::path path = Path("camera.yml");
  WriteCameraCalibration({first, "a"}, path, CalibrationFormat::kOpenCvYaml);
  WriteCameraCalibration({second, "b"}, path, CalibrationFormat::kOpenCvYaml);
  const CameraCalibration read = ReadCameraCalibration(path);
  ExpectSameCamera(read.model, second);
  EXPECT_EQ(read.name, "b");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1);
}

TEST_F(CalibrationIoTest, WritersRejectWhatTheFormatCannotHold) {
  std::mt19937 rng(25);
  const RandomStereo s = MakeStereo(rng, DistortionModel::kRadialTangential);
  EXPECT_THROW(WriteStereoCalibration(s.calibration, Path("s.yaml"), CalibrationFormat::kRosYaml),
               InvalidArgument);
  StereoCalibration mixed = s.calibration;
  mixed.right = RandomCamera(rng, DistortionModel::kFisheye);
  mixed.right = CameraModel(s.calibration.left.intrinsics(), mixed.right.distortion());
  EXPECT_THROW(WriteStereoCalibration(mixed, Path("s.yml"), CalibrationFormat::kOpenCvYaml),
               InvalidArgument);
  StereoCalibration sized = s.calibration;
  sized.right = RandomCamera(rng, DistortionModel::kRadialTangential);
  EXPECT_THROW(WriteStereoCalibration(sized, Path("s.yml"), CalibrationFormat::kOpenCvYaml),
               InvalidArgument);
  StereoCalibration not_rotation = s.calibration;
  not_rotation.R(0, 0) = 2.0;
  EXPECT_THROW(WriteStereoCalibration(not_rotation, Path("s.yml"), CalibrationFormat::kOpenCvYaml),
               InvalidArgument);
  EXPECT_THROW(WriteCameraCalibration({s.calibration.left, "two\nlines"}, Path("c.yml"),
                                      CalibrationFormat::kOpenCvYaml),
               InvalidArgument);
  EXPECT_TRUE(fs::is_empty(dir_));
}

}  // namespace
}  // namespace saccade::geometry
