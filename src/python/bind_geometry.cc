// saccade.geometry: the camera model (OpenCV's, to the digit), calibration files, poses and
// triangulation. Points are numpy arrays of float64; poses 4x4 matrices.
#include <pybind11/eigen.h>
#include <pybind11/operators.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"
#include "saccade/geometry/calibration_io.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/triangulation.h"

namespace saccade::python {

namespace {

// Intrinsics: the image size and K.
void BindIntrinsics(py::module_& m) {
  using namespace geometry;
  py::class_<Intrinsics>(m, "Intrinsics",
                         "Image size and K = [fx skew cx; 0 fy cy; 0 0 1] in pixels "
                         "(include/saccade/geometry/intrinsics.h).")
      .def(py::init<int, int, double, double, double, double, double>(), "width"_a, "height"_a,
           "fx"_a, "fy"_a, "cx"_a, "cy"_a, "skew"_a = 0.0,
           "Raises InvalidArgument naming the field when a size is not positive or a focal "
           "length not positive and finite.")
      .def_static("from_matrix", &Intrinsics::FromMatrix, "K"_a, "width"_a, "height"_a,
                  "From a 3x3 upper-triangular K with K[2,2] = 1.")
      .def_property_readonly("width", &Intrinsics::width)
      .def_property_readonly("height", &Intrinsics::height)
      .def_property_readonly("fx", &Intrinsics::fx)
      .def_property_readonly("fy", &Intrinsics::fy)
      .def_property_readonly("cx", &Intrinsics::cx)
      .def_property_readonly("cy", &Intrinsics::cy)
      .def_property_readonly("skew", &Intrinsics::skew)
      .def_property_readonly("K", &Intrinsics::Matrix, "The 3x3 camera matrix.")
      .def("horizontal_fov", &Intrinsics::HorizontalFov, "Radians, across the image edges.")
      .def("vertical_fov", &Intrinsics::VerticalFov, "Radians, across the image edges.")
      .def(py::self == py::self)
      .def("__repr__", [](const Intrinsics& k) {
        return "Intrinsics(" + std::to_string(k.width()) + "x" + std::to_string(k.height()) +
               ", fx=" + std::to_string(k.fx()) + ", fy=" + std::to_string(k.fy()) +
               ", cx=" + std::to_string(k.cx()) + ", cy=" + std::to_string(k.cy()) + ")";
      });
}

// Distortion: the lens models and their coefficients.
void BindDistortion(py::module_& m) {
  using namespace geometry;
  py::class_<Distortion>(m, "Distortion",
                         "A lens distortion model and its coefficients, OpenCV's order "
                         "(include/saccade/geometry/distortion.h).")
      .def(py::init<>(), "No distortion.")
      .def_static(
          "radial_tangential",
          [](const std::vector<double>& c) { return Distortion::RadialTangential(c); },
          "coefficients"_a, "k1 k2 p1 p2 [k3 [k4 k5 k6]] as cv::projectPoints.")
      .def_static(
          "fisheye", [](const std::vector<double>& c) { return Distortion::Fisheye(c); },
          "coefficients"_a, "Kannala-Brandt k1 k2 k3 k4 as cv::fisheye::projectPoints.")
      .def_property_readonly(
          "model", [](const Distortion& d) { return ToString(d.model()); },
          "'none', 'radtan' or 'fisheye'.")
      .def_property_readonly("coefficients", &Distortion::coefficients)
      .def("is_identity", &Distortion::IsIdentity)
      .def("distort", &Distortion::Distort, "xy"_a,
           "Distorted normalized coordinates of undistorted (x, y) = (X/Z, Y/Z).")
      .def(py::self == py::self);
}

// CameraModel: points to pixels and back.
void BindCameraModel(py::module_& m) {
  using namespace geometry;
  py::class_<CameraModel>(m, "CameraModel",
                          "Intrinsics and distortion: points to pixels as cv::projectPoints, "
                          "pixels to rays.")
      .def(py::init<const Intrinsics&, const Distortion&>(), "intrinsics"_a,
           "distortion"_a = Distortion())
      .def_property_readonly("intrinsics", &CameraModel::intrinsics)
      .def_property_readonly("distortion", &CameraModel::distortion)
      .def(
          "project",
          [](const CameraModel& model, const Eigen::Vector3d& p_C) -> py::object {
            const auto uv = model.Project(p_C);
            return uv ? py::cast(*uv) : py::none();
          },
          "p_C"_a,
          "Pixel (u, v) of a point in the camera's optical frame (metres); None when the model "
          "cannot image it (behind a pinhole camera).")
      .def(
          "project_points",
          [](const CameraModel& model, const Eigen::Matrix<double, Eigen::Dynamic, 3>& points) {
            Eigen::Matrix<double, Eigen::Dynamic, 2> uv(points.rows(), 2);
            for (Eigen::Index i = 0; i < points.rows(); ++i) {
              const auto p = model.Project(points.row(i).transpose());
              uv.row(i) = p ? Eigen::RowVector2d(p->transpose())
                            : Eigen::RowVector2d::Constant(std::nan(""));
            }
            return uv;
          },
          "points_C"_a, "N x 3 points to N x 2 pixels (NaN where a point cannot be imaged).")
      .def(
          "unproject",
          [](const CameraModel& model, const Eigen::Vector2d& uv) -> py::object {
            const auto ray = model.Unproject(uv);
            return ray ? py::cast(*ray) : py::none();
          },
          "uv"_a, "Unit ray through pixel (u, v), distortion removed; None when it diverges.")
      .def("contains", &CameraModel::Contains, "uv"_a)
      .def(py::self == py::self);
}

// Calibrated cameras and stereo pairs, and their files.
void BindCalibration(py::module_& m) {
  using namespace geometry;
  py::class_<CameraCalibration>(m, "CameraCalibration", "A calibrated camera and its name.")
      .def(py::init<CameraModel, std::string>(), "model"_a, "name"_a = "")
      .def_readwrite("model", &CameraCalibration::model)
      .def_readwrite("name", &CameraCalibration::name);
  py::class_<StereoCalibration>(
      m, "StereoCalibration", "Two cameras and the right camera's pose in the left: p2 = R p1 + T.")
      .def_readonly("left", &StereoCalibration::left)
      .def_readonly("right", &StereoCalibration::right)
      .def_readonly("R", &StereoCalibration::R)
      .def_readonly("T", &StereoCalibration::T);

  const auto size_of = [](const std::optional<std::pair<int, int>>& size) {
    return size ? std::optional<ImageSize>(ImageSize{size->first, size->second}) : std::nullopt;
  };
  m.def(
      "read_camera_calibration",
      [size_of](const std::filesystem::path& path, std::optional<std::pair<int, int>> size) {
        return ReadCameraCalibration(path, size_of(size));
      },
      "path"_a, "size"_a = py::none(),
      "Reads one camera (OpenCV YAML/XML, ROS YAML). `size` (width, height) is used when the "
      "file has none. Raises FileError with file:line: key.");
  m.def(
      "write_camera_calibration",
      [](const CameraCalibration& calibration, const std::filesystem::path& path,
         const std::string& format) {
        CalibrationFormat f = CalibrationFormat::kOpenCvYaml;
        if (format == "opencv_xml") {
          f = CalibrationFormat::kOpenCvXml;
        } else if (format == "ros_yaml") {
          f = CalibrationFormat::kRosYaml;
        } else if (format != "opencv_yaml") {
          throw InvalidArgument("write_camera_calibration: format '" + format +
                                "'; expected 'opencv_yaml', 'opencv_xml' or 'ros_yaml'");
        }
        WriteCameraCalibration(calibration, path, f);
      },
      "calibration"_a, "path"_a, "format"_a = "opencv_yaml");
  m.def(
      "read_stereo_calibration",
      [size_of](const std::filesystem::path& path, std::optional<std::filesystem::path> extrinsics,
                std::optional<std::pair<int, int>> size) {
        return ReadStereoCalibration(path, extrinsics, size_of(size));
      },
      "path"_a, "extrinsics_path"_a = py::none(), "size"_a = py::none(),
      "Reads M1 D1 M2 D2 R T (OpenCV YAML or XML).");
}

// Rotations and poses.
void BindPoses(py::module_& m) {
  using namespace geometry;
  m.def("rotation_from_rpy", &RotationFromRpy, "roll"_a, "pitch"_a, "yaw"_a,
        "R = Rz(yaw) Ry(pitch) Rx(roll) (REP 103), radians.");
  m.def("rpy_from_rotation", &RpyFromRotation, "R"_a);
  m.def(
      "make_pose",
      [](const Eigen::Matrix3d& R, const Eigen::Vector3d& t) { return MakePose(R, t).matrix(); },
      "R"_a, "t"_a, "A 4x4 pose from a rotation and a translation.");
}

// Rays and triangulation (seed section 4.2).
void BindTriangulation(py::module_& m) {
  using namespace geometry;
  py::class_<Ray>(m, "Ray", "A ray: origin (metres) and unit direction.")
      .def(py::init([](const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
             if (!(direction.norm() > 0.0) || !direction.allFinite() || !origin.allFinite()) {
               throw InvalidArgument("Ray: expected a finite origin and a non-zero direction");
             }
             return Ray{origin, direction.normalized()};
           }),
           "origin"_a, "direction"_a)
      .def_readonly("origin", &Ray::origin)
      .def_readonly("direction", &Ray::direction);
  py::class_<TriangulationResult>(m, "TriangulationResult")
      .def_readonly("point", &TriangulationResult::point)
      .def_readonly("gap", &TriangulationResult::gap, "Shortest distance between the rays (m).")
      .def_readonly("parallel", &TriangulationResult::parallel)
      .def_readonly("behind", &TriangulationResult::behind)
      .def_property_readonly("ok", &TriangulationResult::ok);
  m.def("triangulate_midpoint", &TriangulateMidpoint, "a"_a, "b"_a, "min_angle"_a = 1e-9,
        "Midpoint of the shortest segment between two rays (seed section 4.2).");
  m.def("triangulate_dlt", &TriangulateDlt, "view_a"_a, "xy_a"_a, "view_b"_a, "xy_b"_a,
        "Linear triangulation from two 3x4 [R|t] world-to-camera views and normalized points.");
}

}  // namespace

void BindGeometry(py::module_& m) {
  BindIntrinsics(m);
  BindDistortion(m);
  BindCameraModel(m);
  BindCalibration(m);
  BindPoses(m);
  BindTriangulation(m);
}

}  // namespace saccade::python
