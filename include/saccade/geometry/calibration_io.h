#pragma once
// Camera calibration files, read and written:
// - OpenCV FileStorage YAML ("%YAML:1.0", !!opencv-matrix) and XML (<opencv_storage>), as
//   OpenCV's calibration samples write them: camera_matrix, distortion_coefficients,
//   image_width, image_height (and fisheye_model: 1 for the fisheye model); the stereo form
//   M1 D1 M2 D2 R T, in one file or split as intrinsics.yml + extrinsics.yml.
// - ROS sensor_msgs/CameraInfo YAML (camera_calibration_parsers): image_width, image_height,
//   camera_name, camera_matrix, distortion_model (plumb_bob, rational_polynomial,
//   equidistant), distortion_coefficients.
// Errors throw saccade::FileError naming the file, the line where known, and the key.
// Writers write a temporary file and rename it: a failed write leaves nothing half-written.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>

#include "saccade/geometry/camera_model.h"

namespace saccade::geometry {

enum class CalibrationFormat { kOpenCvYaml, kOpenCvXml, kRosYaml };

/// A calibrated camera and its name (ROS camera_name; empty when the file has none).
struct CameraCalibration {
  CameraModel model;
  std::string name;
};

/// Two calibrated cameras and the pose of the right (second) camera in the left (first):
/// a point p1 in camera 1's optical frame is p2 = R p1 + T in camera 2's (cv::stereoCalibrate).
struct StereoCalibration {
  CameraModel left;
  CameraModel right;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d T = Eigen::Vector3d::Zero();
};

/// Width and height in pixels, for files that do not store the image size.
struct ImageSize {
  int width = 0;
  int height = 0;
};

/// The format of a file by extension (.xml) and content (ROS files have distortion_model).
CalibrationFormat DetectCalibrationFormat(const std::filesystem::path& path);

/// The image size a calibration file stores (image_width and image_height), std::nullopt when
/// it stores neither; for choosing a camera's mode before its first frame. Throws FileError as
/// the readers (a file with one of the two, or a size that is not positive).
std::optional<ImageSize> ReadCalibrationImageSize(const std::filesystem::path& path);

/// Reads one camera. `size` is used when the file has no image_width/image_height; a file
/// with neither throws FileError naming the missing key.
CameraCalibration ReadCameraCalibration(const std::filesystem::path& path,
                                        std::optional<ImageSize> size = std::nullopt);

/// Writes one camera in the given format.
void WriteCameraCalibration(const CameraCalibration& calibration, const std::filesystem::path& path,
                            CalibrationFormat format);

/// Reads M1 D1 M2 D2 R T (OpenCV YAML or XML). `extrinsics_path` defaults to `path`.
StereoCalibration ReadStereoCalibration(
    const std::filesystem::path& path,
    const std::optional<std::filesystem::path>& extrinsics_path = std::nullopt,
    std::optional<ImageSize> size = std::nullopt);

/// Reads one camera of a stereo file (M1 D1 M2 D2, OpenCV YAML or XML) without needing R and
/// T: `index` 1 reads M1 D1 (the first, left camera), 2 reads M2 D2. This is how stereo_calib's
/// intrinsics.yml is read, which stores no R, T or image size. `size` is used when the file has
/// no image_width/image_height. Throws InvalidArgument for another index, FileError (file, line,
/// key) as ReadCameraCalibration. The name is empty (stereo files store none).
CameraCalibration ReadStereoCameraCalibration(const std::filesystem::path& path, int index,
                                              std::optional<ImageSize> size = std::nullopt);

/// Whether `path` holds a stereo calibration in OpenCV's form (M1 D1 M2 D2, as stereo_calib's
/// intrinsics.yml), rather than one camera. Throws FileError as the readers.
bool IsStereoCalibrationFile(const std::filesystem::path& path);

/// Whether `path` (an OpenCV YAML or XML file) stores the pose of a stereo pair: R and T.
bool HasStereoExtrinsics(const std::filesystem::path& path);

/// Reads a ROS stereo pair: the left and right camera_info files of a calibrated pair, as
/// ROS's camera_calibration writes them (left.yaml, right.yaml). Their rectification_matrix
/// (R1, R2: each camera's optical frame into the shared rectified frame) and projection_matrix
/// (P1, P2 = K' [I | t'], t' the right camera's offset in the rectified frame: P2[0][3] =
/// -fx' * baseline for a horizontal pair) give the right camera's pose in the left, in
/// cv::stereoCalibrate's convention (p2 = R p1 + T): R = R2^T R1, T = R2^T t', where t' =
/// ((P2[0][3] - P1[0][3]) / P2[0][0], (P2[1][3] - P1[1][3]) / P2[1][1], 0). Throws FileError
/// naming the file and key: a missing or malformed matrix, a rectification that is not a
/// rotation, a right projection without a baseline (not a stereo pair).
StereoCalibration ReadRosStereoPair(const std::filesystem::path& left,
                                    const std::filesystem::path& right,
                                    std::optional<ImageSize> size = std::nullopt);

/// Writes M1 D1 M2 D2 R T, image_width and image_height in one OpenCV YAML or XML file.
void WriteStereoCalibration(const StereoCalibration& calibration, const std::filesystem::path& path,
                            CalibrationFormat format);

}  // namespace saccade::geometry
