#pragma once
// A robot from its URDF (issue 42), parsed by Debian's urdfdom: the kinematic tree, the
// visuals with their meshes found on disk, and the cameras of Gazebo's <sensor type="camera">
// blocks, which urdfdom does not read (TinyXML reads them).
//
// Mesh paths (URDF's <mesh filename="...">) resolve as ROS tools resolve them:
//   package://PKG/REST  the first existing file of, in order:
//                         - DIR/REST for `packages: {PKG: DIR}` in the head file (options),
//                         - D/PKG/REST, or D/REST when D's own name is PKG, for each folder D of
//                           $SACCADE_PACKAGE_PATH, then of $ROS_PACKAGE_PATH (':'-separated),
//                         - the same for the URDF's folder and each folder above it;
//   file:///ABS         ABS;
//   a relative path     relative to the URDF's folder; an absolute one as it is.
// A mesh that is not found is an error naming the URI and the folders searched, unless
// options.visuals_optional: then the visual is left out and a warning names it.
//
// Gazebo's camera (gazebo_ros and gz-sim's sensors): the camera looks along the +x axis of
// its frame, z up: frame = the reference link * <pose> (x y z roll pitch yaw, R = Rz Ry Rx).
// saccade's optical frame (OpenCV: x right, y down, z forward) is that frame turned by
// rpy (-pi/2, 0, -pi/2), as ROS's camera_optical frames are. Intrinsics as Gazebo computes
// them: square pixels, fx = fy = width / 2 / tan(horizontal_fov / 2), the principal point at
// the centre of the symmetric frustum, ((width - 1) / 2, (height - 1) / 2) with pixel centres
// at integers (gz-sim's CameraInfo writes width / 2 with pixel edges at integers: the same
// point). <distortion> k1 k2 k3 p1 p2 are OpenCV's radial-tangential coefficients, as gazebo_ros
// publishes them in CameraInfo (D = k1 k2 p1 p2 k3); its <center> must be 0.5 0.5.

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"
#include "saccade/head/kinematic_tree.h"

namespace saccade::head {

/// One <visual> of a link.
struct UrdfVisual {
  enum class Shape { kBox, kCylinder, kSphere, kMesh };
  int link = 0;                                      ///< link index in the tree
  geometry::Pose X_LV = geometry::Pose::Identity();  ///< the visual in its link
  Shape shape = Shape::kBox;
  /// Box: its sizes (x, y, z); cylinder: (radius, radius, length) along its z; sphere:
  /// (radius, radius, radius); mesh: unused (metres).
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  std::string mesh_uri;                             ///< as written in the URDF
  std::filesystem::path mesh_path;                  ///< the file found
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();  ///< the mesh's <mesh scale>
  std::optional<Eigen::Vector4d> rgba;              ///< the <material>'s colour, 0..1
  std::string material;                             ///< the material's name, if any
};

/// A Gazebo <sensor type="camera"> block.
struct GazeboCamera {
  std::string name;  ///< the sensor's name attribute
  std::string link;  ///< <gazebo reference="...">
  int link_index = 0;
  geometry::Pose X_LS = geometry::Pose::Identity();  ///< <pose>: the sensor frame in the link
  double horizontal_fov = 0.0;                       ///< rad, in (0, pi)
  int width = 0;                                     ///< pixels
  int height = 0;
  double near = 0.1;   ///< <clip><near>, m (SDF's default)
  double far = 100.0;  ///< <clip><far>, m
  /// k1, k2, p1, p2, k3 (OpenCV's order); all 0 without <distortion>.
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};
  int line = 0;  ///< the <sensor> element's line

  /// The camera model as Gazebo computes it (see the file's header).
  geometry::CameraModel Model() const;
  /// The OpenCV optical frame in the link: X_LS * R(rpy = -pi/2, 0, -pi/2).
  geometry::Pose X_LOptical() const;
};

struct UrdfOptions {
  /// Meshes that are not found are left out with a warning instead of an error.
  bool visuals_optional = false;
  /// package:// roots named by the head file: package name -> folder.
  std::map<std::string, std::filesystem::path> packages;
};

/// A parsed URDF.
struct UrdfModel {
  std::string name;  ///< <robot name>
  KinematicTree tree;
  std::vector<UrdfVisual> visuals;
  std::vector<GazeboCamera> cameras;
  std::string xml;  ///< the file's text (ROS's robot_description)
  std::string source;

  /// The Gazebo camera of that sensor name; nullptr when there is none.
  const GazeboCamera* FindCamera(const std::string& sensor_name) const;
};

/// Loads a URDF file. Throws saccade::FileError naming the file, the element (line where known)
/// and what was expected: the file cannot be read; it is not XML; its root is not <robot>;
/// urdfdom rejects it (its message is quoted); a joint is floating or planar; the tree is
/// invalid (KinematicTree::Build); a mesh is missing (unless optional); a Gazebo camera's
/// reference link does not exist, or it has no <horizontal_fov> in (0, pi), no <image> width or
/// height > 0, a bad <pose>, <clip> or <distortion>.
UrdfModel LoadUrdfFile(const std::filesystem::path& path, const UrdfOptions& options = {});
/// Same from text; `source` names it in errors, `base_dir` is where relative meshes are.
UrdfModel ParseUrdf(const std::string& xml, const std::string& source,
                    const std::filesystem::path& base_dir, const UrdfOptions& options = {});

/// Where a URDF mesh URI points, by the rules of this file's header; std::nullopt when no file
/// exists there. `searched` (optional) receives the candidates tried, for messages.
std::optional<std::filesystem::path> ResolveMeshUri(const std::string& uri,
                                                    const std::filesystem::path& base_dir,
                                                    const UrdfOptions& options,
                                                    std::vector<std::string>* searched = nullptr);

}  // namespace saccade::head
