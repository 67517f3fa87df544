#include "saccade/head/head_description.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "saccade/core/error.h"

namespace saccade::head {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Values read from YAML go through one multiplication (deg -> rad, mm / um): a few ulps.
constexpr double kParseTolerance = 1e-12;

const std::string kPopeyePath = SACCADE_SOURCE_DIR "/robots/popeye.yaml";

// A valid description; tests break one entry at a time.
const std::string kValid = R"(name: test_head
geometry:
  half_baseline: 0.1
  D: 0.0
  H: 0.0
  delta_left: 0.0
  delta_right: 0.0
joints:
  pan:
    limits_deg: [-90, 90]
    max_velocity_deg: 300
    max_acceleration_deg: 3000
  tilt:
    limits_deg: [-45, 45]
    max_velocity_deg: 300
    max_acceleration_deg: 3000
  left:
    limits_deg: [-45, 45]
    max_velocity_deg: 600
    max_acceleration_deg: 6000
  right:
    limits_deg: [-45, 45]
    max_velocity_deg: 600
    max_acceleration_deg: 6000
pose:
  position: [0.0, 0.0, 1.2]
  rpy_deg: [0, 0, 0]
cameras:
  left:
    width: 1024
    height: 768
    focal_length_mm: 6.0
    pixel_size_um: 4.65
  right:
    width: 1024
    height: 768
    fx: 1290.0
    fy: 1291.0
    cx: 500.0
    cy: 380.0
)";

// Replaces the first occurrence of `from` (which must exist) by `to`.
std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << from << "' not in the text";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// 1-based line of the first occurrence of `needle`.
int LineOf(const std::string& text, const std::string& needle) {
  const auto at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << "test bug: '" << needle << "' not in the text";
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

// Loads `text` and expects a FileError at `line` naming `key`, with `what` in the message.
void ExpectFileError(const std::string& text, int line, const std::string& key,
                     const std::string& what) {
  try {
    HeadDescription::FromYamlString(text, "bad.yaml");
    ADD_FAILURE() << "no FileError for key " << key;
  } catch (const FileError& error) {
    const std::string message = error.what();
    EXPECT_EQ(error.file(), "bad.yaml");
    EXPECT_EQ(error.line(), line) << message;
    EXPECT_EQ(error.key(), key) << message;
    const std::string prefix =
        "bad.yaml:" + std::to_string(line) + ": " + (key.empty() ? "" : key + ": ");
    EXPECT_EQ(message.rfind(prefix, 0), 0u) << message << "\nexpected prefix: " << prefix;
    EXPECT_NE(message.find(what), std::string::npos) << message << "\nexpected: " << what;
  }
}

TEST(HeadDescriptionTest, PopeyeFileLoadsWithFlea2Intrinsics) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  EXPECT_EQ(head.name(), "popeye");
  const double f = 6.0 / 0.00465;  // 6 mm lens, 4.65 um pixels
  for (const auto* camera : {&head.left_camera(), &head.right_camera()}) {
    const auto& K = camera->intrinsics();
    EXPECT_EQ(K.width(), 1024);
    EXPECT_EQ(K.height(), 768);
    EXPECT_NEAR(K.fx(), f, kParseTolerance * f);
    EXPECT_NEAR(K.fy(), f, kParseTolerance * f);
    EXPECT_NEAR(K.fx(), 1290.32, 0.005);
    EXPECT_EQ(K.cx(), 511.5);
    EXPECT_EQ(K.cy(), 383.5);
    EXPECT_EQ(K.skew(), 0.0);
    EXPECT_EQ(camera->distortion().model(), geometry::DistortionModel::kNone);
  }
  EXPECT_EQ(head.geometry().B, 0.1);
  EXPECT_EQ(head.geometry().D, 0.0);
  EXPECT_EQ(head.geometry().H, 0.0);
  EXPECT_NEAR(head.limits(Joint::kPan).min, -90 * kDeg, kParseTolerance);
  EXPECT_NEAR(head.limits(Joint::kPan).max, 90 * kDeg, kParseTolerance);
  EXPECT_NEAR(head.limits(Joint::kTilt).max, 45 * kDeg, kParseTolerance);
  for (const Joint joint : kAllJoints) {
    EXPECT_GT(head.limits(joint).max_velocity, 1.0) << JointName(joint);  // rad/s
    EXPECT_GT(head.limits(joint).max_acceleration, head.limits(joint).max_velocity);
  }
  EXPECT_TRUE(head.X_WB().translation().isApprox(Eigen::Vector3d(0, 0, 1.2)));
  EXPECT_TRUE(head.X_WB().linear().isIdentity());
}

TEST(HeadDescriptionTest, ValidStringLoadsBothFocalLengthForms) {
  const HeadDescription head = HeadDescription::FromYamlString(kValid, "valid.yaml");
  EXPECT_EQ(head.name(), "test_head");
  // Default principal point: the image centre with pixel centres at integers.
  EXPECT_EQ(head.left_camera().intrinsics().cx(), 511.5);
  EXPECT_EQ(head.left_camera().intrinsics().cy(), 383.5);
  EXPECT_EQ(head.right_camera().intrinsics().fx(), 1290.0);
  EXPECT_EQ(head.right_camera().intrinsics().fy(), 1291.0);
  EXPECT_EQ(head.right_camera().intrinsics().cx(), 500.0);
  EXPECT_EQ(head.right_camera().intrinsics().cy(), 380.0);
}

TEST(HeadDescriptionTest, RadianKeysAndRpyAndDistortionAreRead) {
  std::string text = Replace(kValid, "    limits_deg: [-45, 45]\n    max_velocity_deg: 300",
                             "    limits: [-0.5, 0.25]\n    max_velocity: 2.0");
  text = Replace(text, "rpy_deg: [0, 0, 0]", "rpy: [0.1, -0.2, 0.3]");
  text = Replace(text, "    cy: 380.0\n",
                 "    cy: 380.0\n    distortion: {model: radtan, coefficients: [-0.2, 0.05, "
                 "0.001, -0.002, 0.01]}\n");
  text = Replace(text, "  D: 0.0", "  D: 0.02");
  const HeadDescription head = HeadDescription::FromYamlString(text, "rad.yaml");
  EXPECT_EQ(head.limits(Joint::kTilt).min, -0.5);
  EXPECT_EQ(head.limits(Joint::kTilt).max, 0.25);
  EXPECT_EQ(head.limits(Joint::kTilt).max_velocity, 2.0);
  EXPECT_NEAR(head.limits(Joint::kTilt).max_acceleration, 3000 * kDeg, kParseTolerance);
  EXPECT_EQ(head.geometry().D, 0.02);
  const Eigen::Matrix3d expected = geometry::RotationFromRpy(0.1, -0.2, 0.3);
  EXPECT_TRUE(head.X_WB().linear().isApprox(expected, kParseTolerance));
  const auto& distortion = head.right_camera().distortion();
  EXPECT_EQ(distortion.model(), geometry::DistortionModel::kRadialTangential);
  ASSERT_EQ(distortion.coefficients().size(), 8u);
  EXPECT_EQ(distortion.coefficients()[0], -0.2);
  EXPECT_EQ(distortion.coefficients()[4], 0.01);
}

TEST(HeadDescriptionTest, OptionalGeometryOffsetsDefaultToZero) {
  std::string text =
      Replace(kValid, "  D: 0.0\n  H: 0.0\n  delta_left: 0.0\n  delta_right: 0.0\n", "");
  const HeadDescription head = HeadDescription::FromYamlString(text, "defaults.yaml");
  EXPECT_EQ(head.geometry().D, 0.0);
  EXPECT_EQ(head.geometry().H, 0.0);
  EXPECT_EQ(head.geometry().delta_l, 0.0);
  EXPECT_EQ(head.geometry().delta_r, 0.0);
}

TEST(HeadDescriptionTest, PopeyeServosMapJointsOntoDynamixelTicks) {
  const HeadDescription head = HeadDescription::FromYamlFile(kPopeyePath);
  ASSERT_TRUE(head.HasServos());
  const ServoMapping& tilt = *head.servo(Joint::kTilt);
  EXPECT_EQ(tilt.id, 2);
  EXPECT_EQ(tilt.direction, -1);
  EXPECT_NEAR(tilt.zero_offset, std::numbers::pi, kParseTolerance);
  // Joint 0 is the servo's centre (180 deg); the upside-down tilt servo turns the other way.
  EXPECT_NEAR(tilt.ServoAngle(10 * kDeg), 170 * kDeg, kParseTolerance);
  EXPECT_NEAR(tilt.JointAngle(170 * kDeg), 10 * kDeg, kParseTolerance);
  EXPECT_NEAR(head.servo(Joint::kPan)->ServoAngle(10 * kDeg), 190 * kDeg, kParseTolerance);
  EXPECT_EQ(head.servo(Joint::kRight)->id, 4);
}

TEST(HeadDescriptionTest, ServoMappingIsOptionalAndChecked) {
  const HeadDescription plain = HeadDescription::FromYamlString(kValid, "valid.yaml");
  EXPECT_FALSE(plain.HasServos());
  EXPECT_FALSE(plain.servo(Joint::kPan).has_value());

  const std::string geared = Replace(
      kValid, "    max_acceleration_deg: 3000\n",
      "    max_acceleration_deg: 3000\n    servo: {id: 7, zero_offset: 1.0, gear_ratio: 2.5}\n");
  const HeadDescription head = HeadDescription::FromYamlString(geared, "geared.yaml");
  const ServoMapping& pan = *head.servo(Joint::kPan);
  EXPECT_EQ(pan.id, 7);
  EXPECT_EQ(pan.direction, 1);
  EXPECT_NEAR(pan.ServoAngle(0.2), 1.0 + 2.5 * 0.2, 1e-15);
  EXPECT_NEAR(pan.JointAngle(pan.ServoAngle(-0.3)), -0.3, 1e-15);
  EXPECT_FALSE(head.HasServos());  // only the pan joint has one

  const auto with_servo = [](const std::string& servo) {
    return Replace(kValid, "    max_acceleration_deg: 3000\n",
                   "    max_acceleration_deg: 3000\n    servo: " + servo + "\n");
  };
  std::string text = with_servo("{id: 300}");
  ExpectFileError(text, LineOf(text, "servo:"), "joints.pan.servo.id", "0..252");
  text = with_servo("{id: 1, direction: 2}");
  ExpectFileError(text, LineOf(text, "servo:"), "joints.pan.servo.direction", "1 or -1");
  text = with_servo("{id: 1, gear_ratio: 0}");
  ExpectFileError(text, LineOf(text, "servo:"), "joints.pan.servo.gear_ratio", "positive");
  text = with_servo("{id: 1, zero_offset: 1, zero_offset_deg: 50}");
  ExpectFileError(text, LineOf(text, "servo:"), "joints.pan.servo.zero_offset", "not both");
  text = with_servo("{id: 1, speed: 3}");
  ExpectFileError(text, LineOf(text, "servo:"), "joints.pan.servo.speed", "unknown key 'speed'");
  text = with_servo("{zero_offset: 1}");
  ExpectFileError(text, LineOf(text, "servo:"), "joints.pan.servo", "missing key 'id'");
  // Two joints on one servo id.
  text = Replace(with_servo("{id: 5}"), "    max_acceleration_deg: 6000\n",
                 "    max_acceleration_deg: 6000\n    servo: {id: 5}\n");
  ExpectFileError(text, LineOf(text, "6000\n    servo: {id: 5}") + 1, "joints.left.servo.id",
                  "servo id 5 is already joint pan's");
}

TEST(HeadDescriptionTest, UnknownKeyIsNamedWithItsLine) {
  const std::string text = Replace(kValid, "  H: 0.0\n", "  H: 0.0\n  colour: red\n");
  ExpectFileError(text, LineOf(text, "colour"), "geometry.colour", "unknown key 'colour'");
  const std::string top = kValid + "wheels: 4\n";
  ExpectFileError(top, LineOf(top, "wheels"), "wheels", "expected one of: name, geometry");
}

TEST(HeadDescriptionTest, DuplicateKeyIsAnError) {
  const std::string text = Replace(kValid, "  H: 0.0\n", "  H: 0.0\n  H: 0.1\n");
  ExpectFileError(text, LineOf(text, "  H: 0.1"), "geometry.H", "duplicate key 'H'");
}

TEST(HeadDescriptionTest, MissingKeyNamesTheParentAndTheKey) {
  const std::string tilt =
      "  tilt:\n    limits_deg: [-45, 45]\n    max_velocity_deg: 300\n"
      "    max_acceleration_deg: 3000\n";
  const std::string no_tilt = Replace(kValid, tilt, "");
  ExpectFileError(no_tilt, LineOf(no_tilt, "  pan:"), "joints", "missing key 'tilt'");

  const std::string no_limits = Replace(kValid, "    limits_deg: [-45, 45]\n", "");
  ExpectFileError(no_limits, LineOf(no_limits, "  tilt:\n") + 1, "joints.tilt",
                  "missing key 'limits_deg' (degrees) or 'limits' (radians)");

  const std::string no_baseline = Replace(kValid, "  half_baseline: 0.1\n", "");
  ExpectFileError(no_baseline, LineOf(no_baseline, "  D: 0.0"), "geometry",
                  "missing key 'half_baseline'");

  const std::string no_focal = Replace(kValid, "    fx: 1290.0\n    fy: 1291.0\n", "");
  ExpectFileError(no_focal, LineOf(no_focal, "    width: 1024\n    height: 768\n    cx"),
                  "cameras.right", "missing the focal length");
}

TEST(HeadDescriptionTest, WrongTypesSayWhatWasExpectedAndGot) {
  const std::string scalar = Replace(kValid, "limits_deg: [-45, 45]", "limits_deg: abc");
  ExpectFileError(scalar, LineOf(scalar, "abc"), "joints.tilt.limits_deg",
                  "expected 2 numbers, got 'abc'");

  const std::string three = Replace(kValid, "limits_deg: [-45, 45]", "limits_deg: [-45, 0, 45]");
  ExpectFileError(three, LineOf(three, "[-45, 0, 45]"), "joints.tilt.limits_deg",
                  "expected 2 numbers, got 3");

  const std::string word = Replace(kValid, "half_baseline: 0.1", "half_baseline: wide");
  ExpectFileError(word, LineOf(word, "wide"), "geometry.half_baseline",
                  "expected a number, got 'wide'");

  const std::string element =
      Replace(kValid, "position: [0.0, 0.0, 1.2]", "position: [0.0, x, 1.2]");
  ExpectFileError(element, LineOf(element, "[0.0, x, 1.2]"), "pose.position[1]",
                  "expected a number, got 'x'");

  const std::string fraction = Replace(kValid, "width: 1024", "width: 1024.5");
  ExpectFileError(fraction, LineOf(fraction, "1024.5"), "cameras.left.width",
                  "expected an integer in [1, 1000000], got '1024.5'");

  const std::string map =
      Replace(kValid, "pose:\n  position: [0.0, 0.0, 1.2]\n  rpy_deg: [0, 0, 0]\n", "pose: 3\n");
  ExpectFileError(map, LineOf(map, "pose: 3"), "pose", "expected a map, got '3'");

  ExpectFileError("- a\n- b\n", 1, "", "expected a head description");
}

TEST(HeadDescriptionTest, NonFiniteNumbersAreRejected) {
  const std::string nan = Replace(kValid, "max_velocity_deg: 300", "max_velocity_deg: .nan");
  ExpectFileError(nan, LineOf(nan, ".nan"), "joints.pan.max_velocity_deg",
                  "expected a finite number, got '.nan'");
  const std::string inf = Replace(kValid, "  D: 0.0", "  D: .inf");
  ExpectFileError(inf, LineOf(inf, ".inf"), "geometry.D", "expected a finite number, got '.inf'");
  const std::string list = Replace(kValid, "limits_deg: [-90, 90]", "limits_deg: [-.inf, 90]");
  ExpectFileError(list, LineOf(list, "-.inf"), "joints.pan.limits_deg[0]",
                  "expected a finite number");
}

TEST(HeadDescriptionTest, EmptyRangesAndNonPositiveLimitsAreRejected) {
  const std::string empty = Replace(kValid, "limits_deg: [-45, 45]", "limits_deg: [10, -10]");
  ExpectFileError(empty, LineOf(empty, "[10, -10]"), "joints.tilt.limits_deg",
                  "min < max, got [10, -10] (an empty range)");
  const std::string point = Replace(kValid, "limits_deg: [-45, 45]", "limits_deg: [0, 0]");
  ExpectFileError(point, LineOf(point, "[0, 0]"), "joints.tilt.limits_deg", "an empty range");
  const std::string no_zero = Replace(kValid, "limits_deg: [-45, 45]", "limits_deg: [5, 45]");
  ExpectFileError(no_zero, LineOf(no_zero, "[5, 45]"), "joints.tilt.limits_deg", "contains 0");

  const std::string zero_velocity = Replace(kValid, "max_velocity_deg: 600", "max_velocity_deg: 0");
  ExpectFileError(zero_velocity, LineOf(zero_velocity, "max_velocity_deg: 0"),
                  "joints.left.max_velocity_deg", "expected a positive number, got 0");
  const std::string negative =
      Replace(kValid, "max_acceleration_deg: 3000", "max_acceleration_deg: -1");
  ExpectFileError(negative, LineOf(negative, "max_acceleration_deg: -1"),
                  "joints.pan.max_acceleration_deg", "expected a positive number, got -1");
  const std::string baseline = Replace(kValid, "half_baseline: 0.1", "half_baseline: 0");
  ExpectFileError(baseline, LineOf(baseline, "half_baseline"), "geometry.half_baseline",
                  "expected a positive number");
  const std::string width = Replace(kValid, "width: 1024", "width: -1024");
  ExpectFileError(width, LineOf(width, "-1024"), "cameras.left.width",
                  "expected an integer in [1, 1000000]");
}

TEST(HeadDescriptionTest, ConflictingAndUnknownAlternativesAreRejected) {
  const std::string both = Replace(kValid, "    limits_deg: [-45, 45]\n",
                                   "    limits_deg: [-45, 45]\n    limits: [-1, 1]\n");
  ExpectFileError(both, LineOf(both, "limits: [-1, 1]"), "joints.tilt.limits",
                  "either 'limits' (radians) or 'limits_deg', not both");
  const std::string focal =
      Replace(kValid, "    pixel_size_um: 4.65\n", "    pixel_size_um: 4.65\n    fx: 1000\n");
  ExpectFileError(focal, LineOf(focal, "fx: 1000"), "cameras.left.fx", "not both");
  const std::string model =
      Replace(kValid, "    cy: 380.0\n", "    cy: 380.0\n    distortion: {model: plumb}\n");
  ExpectFileError(model, LineOf(model, "plumb"), "cameras.right.distortion.model",
                  "expected 'none', 'radtan' or 'fisheye', got 'plumb'");
  const std::string count = Replace(kValid, "    cy: 380.0\n",
                                    "    cy: 380.0\n    distortion:\n      model: fisheye\n"
                                    "      coefficients: [0.1, 0.2]\n");
  ExpectFileError(count, LineOf(count, "[0.1, 0.2]"), "cameras.right.distortion.coefficients", "");
}

TEST(HeadDescriptionTest, YamlSyntaxErrorHasItsLine) {
  const std::string text = Replace(kValid, "  pan:\n", "  pan: [unclosed\n");
  try {
    HeadDescription::FromYamlString(text, "syntax.yaml");
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& error) {
    EXPECT_EQ(error.file(), "syntax.yaml");
    EXPECT_GE(error.line(), LineOf(text, "[unclosed"));
    EXPECT_NE(std::string(error.what()).find("YAML syntax error"), std::string::npos);
  }
}

TEST(HeadDescriptionTest, FileErrorsNameThePath) {
  const std::filesystem::path missing = "/nonexistent/saccade/head.yaml";
  try {
    HeadDescription::FromYamlFile(missing);
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& error) {
    EXPECT_EQ(error.file(), missing.string());
    EXPECT_NE(std::string(error.what()).find("cannot open"), std::string::npos);
  }
  const std::filesystem::path bad =
      std::filesystem::temp_directory_path() / "saccade_head_description_test_bad.yaml";
  const std::string text = Replace(kValid, "max_velocity_deg: 300", "max_velocity_deg: fast");
  std::ofstream(bad) << text;
  try {
    HeadDescription::FromYamlFile(bad);
    ADD_FAILURE() << "no FileError";
  } catch (const FileError& error) {
    const std::string prefix = bad.string() + ":" + std::to_string(LineOf(text, "fast")) +
                               ": joints.pan.max_velocity_deg: ";
    EXPECT_EQ(std::string(error.what()).rfind(prefix, 0), 0u) << error.what();
  }
  std::filesystem::remove(bad);
}

TEST(HeadDescriptionTest, ADeviceOrFolderIsRefusedBeforeReading) {
  // Issue 18: /dev/zero never ends; reading it whole took all memory.
  for (const char* path : {"/dev/zero", "/tmp"}) {
    try {
      HeadDescription::FromYamlFile(path);
      ADD_FAILURE() << "no FileError for " << path;
    } catch (const FileError& error) {
      EXPECT_EQ(error.file(), path);
      EXPECT_NE(std::string(error.what()).find("not a regular file"), std::string::npos)
          << error.what();
    }
  }
}

// The validating constructor, for descriptions built in code.
class HeadDescriptionConstructorTest : public ::testing::Test {
 protected:
  HeadGeometry geometry_;
  std::array<JointLimits, 4> limits_{
      JointLimits{-1.0, 1.0, 5.0, 50.0}, JointLimits{-0.5, 0.5, 5.0, 50.0},
      JointLimits{-0.7, 0.7, 10.0, 100.0}, JointLimits{-0.7, 0.7, 10.0, 100.0}};
  geometry::CameraModel camera_{geometry::Intrinsics(640, 480, 500.0, 500.0, 319.5, 239.5)};

  void ExpectInvalid(const std::string& what) {
    try {
      HeadDescription("h", geometry_, limits_, geometry::Pose::Identity(), camera_, camera_);
      ADD_FAILURE() << "no InvalidArgument for " << what;
    } catch (const InvalidArgument& error) {
      EXPECT_NE(std::string(error.what()).find(what), std::string::npos) << error.what();
    }
  }
};

TEST_F(HeadDescriptionConstructorTest, RejectsBadFieldsNamingThem) {
  geometry_.B = 0.0;
  ExpectInvalid("geometry.B");
  geometry_.B = 0.1;
  geometry_.H = std::nan("");
  ExpectInvalid("geometry.H");
  geometry_.H = 0.0;
  limits_[1].min = 0.6;
  ExpectInvalid("joint tilt");
  limits_[1].min = 0.1;
  ExpectInvalid("contain 0");
  limits_[1].min = -0.5;
  limits_[3].max_velocity = 0.0;
  ExpectInvalid("joint right: max_velocity");
  limits_[3].max_velocity = 1.0;
  limits_[2].max_acceleration = -1.0;
  ExpectInvalid("joint left: max_acceleration");
}

TEST_F(HeadDescriptionConstructorTest, JointStateAccessAndLimitChecks) {
  const HeadDescription head("h", geometry_, limits_, geometry::Pose::Identity(), camera_, camera_);
  PopeyeJoints q{0.1, 0.2, -0.3, 0.4};
  EXPECT_EQ(q[Joint::kPan], 0.1);
  EXPECT_EQ(q[Joint::kTilt], 0.2);
  EXPECT_EQ(q[Joint::kLeft], -0.3);
  EXPECT_EQ(q[Joint::kRight], 0.4);
  q[Joint::kRight] = 0.5;
  EXPECT_EQ(q.right, 0.5);
  EXPECT_STREQ(JointName(Joint::kTilt), "tilt");
  EXPECT_TRUE(head.WithinLimits(q));
  EXPECT_NO_THROW(head.CheckLimits(q));
  q.tilt = 0.6;  // limits [-0.5, 0.5] rad
  EXPECT_FALSE(head.WithinLimits(q));
  try {
    head.CheckLimits(q);
    ADD_FAILURE() << "no InvalidArgument";
  } catch (const InvalidArgument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("joint tilt = 34.3775 deg"), std::string::npos) << message;
    EXPECT_NE(message.find("[-28.6479, 28.6479] deg"), std::string::npos) << message;
  }
  q.tilt = 0.5;  // the bounds themselves are inside
  EXPECT_TRUE(head.WithinLimits(q));
}

}  // namespace
}  // namespace saccade::head
