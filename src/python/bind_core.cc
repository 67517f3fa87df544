// saccade.core: images as numpy arrays without a copy, and the JSON <-> Python conversion.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>

#include "python/internal_bindings.h"
#include "saccade/core/error.h"
#include "saccade/geometry/image_camera.h"

namespace saccade::python {
namespace {

// numpy's shape and dtype of a pixel format: (channels, item size, format string).
struct PixelLayout {
  int channels;
  int item_size;
  std::string format;
};

PixelLayout LayoutOf(PixelFormat format) {
  switch (format) {
    case PixelFormat::kGray8:
      return {1, 1, py::format_descriptor<uint8_t>::format()};
    case PixelFormat::kRgb8:
      return {3, 1, py::format_descriptor<uint8_t>::format()};
    case PixelFormat::kRgba8:
      return {4, 1, py::format_descriptor<uint8_t>::format()};
    case PixelFormat::kGray16:
      return {1, 2, py::format_descriptor<uint16_t>::format()};
    case PixelFormat::kFloat32:
      return {1, 4, py::format_descriptor<float>::format()};
    case PixelFormat::kUint32:
      return {1, 4, py::format_descriptor<uint32_t>::format()};
    case PixelFormat::kBayerRggb8:
    case PixelFormat::kBayerBggr8:
    case PixelFormat::kBayerGbrg8:
    case PixelFormat::kBayerGrbg8:
      return {1, 1, py::format_descriptor<uint8_t>::format()};
    case PixelFormat::kBayerRggb16:
    case PixelFormat::kBayerBggr16:
    case PixelFormat::kBayerGbrg16:
    case PixelFormat::kBayerGrbg16:
      return {1, 2, py::format_descriptor<uint16_t>::format()};
  }
  return {1, 1, py::format_descriptor<uint8_t>::format()};
}

py::buffer_info BufferOf(const ImageRef& ref) {
  const Image& image = *ref.image;
  const PixelLayout layout = LayoutOf(image.format());
  std::vector<py::ssize_t> shape{image.height(), image.width()};
  std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(image.stride()),
                                   layout.channels * layout.item_size};
  if (layout.channels > 1) {
    shape.push_back(layout.channels);
    strides.push_back(layout.item_size);
  }
  // The pixels are shared with every other holder of the frame (DESIGN.md): read-only.
  return py::buffer_info(const_cast<uint8_t*>(image.data()), layout.item_size, layout.format,
                         static_cast<py::ssize_t>(shape.size()), shape, strides,
                         /*readonly=*/true);
}

}  // namespace

py::object ImageArray(std::shared_ptr<const Image> image) {
  if (!image) return py::none();
  py::object owner = py::cast(ImageRef{std::move(image)});
  const py::buffer_info info = BufferOf(owner.cast<const ImageRef&>());
  py::array array(py::dtype(info), info.shape, info.strides, info.ptr, owner);
  array.attr("setflags")("write"_a = false);
  return array;
}

Eigen::Matrix4d PoseToMatrix(const geometry::Pose& pose) { return pose.matrix(); }

geometry::Pose PoseFromMatrix(const Eigen::Matrix4d& matrix, const char* what) {
  // A rotation to 1e-6 (poses typed by hand, or through float32, are rigid to that).
  constexpr double kRigidTolerance = 1e-6;
  const Eigen::Matrix3d R = matrix.topLeftCorner<3, 3>();
  if (!matrix.allFinite() || !matrix.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)) ||
      !(R.transpose() * R).isIdentity(kRigidTolerance) ||
      std::abs(R.determinant() - 1.0) > kRigidTolerance) {
    throw InvalidArgument(std::string(what) +
                          ": expected a 4x4 rigid transform (a rotation, a translation, last row "
                          "0 0 0 1)");
  }
  geometry::Pose pose = geometry::Pose::Identity();
  pose.linear() = R;
  pose.translation() = matrix.topRightCorner<3, 1>();
  return pose;
}

py::object JsonToPython(const nlohmann::json& json) {
  switch (json.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(json.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(json.get<int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(json.get<uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(json.get<double>());
    case nlohmann::json::value_t::string:
      return py::str(json.get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list list;
      for (const auto& item : json) list.append(JsonToPython(item));
      return list;
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (const auto& [key, item] : json.items()) dict[py::str(key)] = JsonToPython(item);
      return dict;
    }
    default:
      return py::none();
  }
}

nlohmann::json JsonFromPython(const py::handle& value, const std::string& what) {
  if (value.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
  if (py::isinstance<py::int_>(value)) return value.cast<int64_t>();
  if (py::isinstance<py::float_>(value)) return value.cast<double>();
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<py::dict>(value)) {
    nlohmann::json object = nlohmann::json::object();
    for (const auto& [key, item] : value.cast<py::dict>()) {
      const std::string name = py::str(key);
      object[name] = JsonFromPython(item, what + "." + name);
    }
    return object;
  }
  // numpy scalars and arrays (points, joints) as numbers and lists.
  if (py::hasattr(value, "tolist")) return JsonFromPython(value.attr("tolist")(), what);
  if (py::isinstance<py::sequence>(value)) {
    nlohmann::json list = nlohmann::json::array();
    int index = 0;
    for (const auto& item : value.cast<py::sequence>()) {
      list.push_back(JsonFromPython(item, what + "[" + std::to_string(index++) + "]"));
    }
    return list;
  }
  throw InvalidArgument(what + ": a " + std::string(py::str(value.get_type().attr("__name__"))) +
                        " cannot be sent as a message field (expected numbers, strings, lists, "
                        "dicts or None)");
}

void BindCore(py::module_& m) {
  py::class_<ImageRef>(m, "Image", py::buffer_protocol(),
                       "An image owned by C++ (shared with the pipeline, never copied). Its "
                       "pixels are a read-only numpy array without a copy: `image.array` or "
                       "`numpy.asarray(image)`; the array's base keeps the image alive.")
      .def_buffer(&BufferOf)
      .def_property_readonly(
          "array", [](const ImageRef& ref) { return ImageArray(ref.image); },
          "The pixels, height x width [x channels], no copy (read-only).")
      .def_property_readonly("width", [](const ImageRef& ref) { return ref.image->width(); })
      .def_property_readonly("height", [](const ImageRef& ref) { return ref.image->height(); })
      .def_property_readonly(
          "format", [](const ImageRef& ref) { return std::string(ToString(ref.image->format())); },
          "'rgb8', 'gray8', 'float32' (depth, metres), 'uint32' (ids), ...")
      .def_property_readonly(
          "data_address",
          [](const ImageRef& ref) { return reinterpret_cast<std::uintptr_t>(ref.image->data()); },
          "Address of the first pixel (to check that nothing was copied).")
      .def_property_readonly("camera",
                             [](const ImageRef& ref) { return ref.image->metadata().camera; })
      .def_property_readonly(
          "time", [](const ImageRef& ref) { return ref.image->metadata().time; },
          "Seconds (simulation or capture time).")
      .def_property_readonly("frame_index",
                             [](const ImageRef& ref) { return ref.image->metadata().frame_index; })
      .def_property_readonly(
          "exposure_s", [](const ImageRef& ref) { return ref.image->metadata().exposure_s; },
          "The exposure time the frame was taken with, seconds (0: an instant).")
      .def_property_readonly(
          "gain_db", [](const ImageRef& ref) { return ref.image->metadata().gain_db; },
          "The gain the frame was taken with, dB.")
      .def_property_readonly(
          "focus_m", [](const ImageRef& ref) { return ref.image->metadata().focus_m; },
          "The focus distance the frame was taken with, metres (0: none).")
      .def_property_readonly(
          "joints",
          [](const ImageRef& ref) -> py::object {
            const ImageMetadata& meta = ref.image->metadata();
            if (!meta.has_joints) return py::none();
            return py::cast(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
                meta.joints.data(), static_cast<Eigen::Index>(meta.joints.size()))));
          },
          "the head's joints at capture, in its order (POPEYE: pan, tilt, left, right; rad); None "
          "when the camera is not on a head.")
      .def_property_readonly(
          "K",
          [](const ImageRef& ref) -> py::object {
            const geometry::CameraModel* model = geometry::FindCameraModel(ref.image->metadata());
            if (model == nullptr) return py::none();
            return py::cast(model->intrinsics().Matrix());
          },
          "The 3x3 camera matrix of the image as it is; None when it carries no camera.")
      .def_property_readonly(
          "camera_model",
          [](const ImageRef& ref) -> py::object {
            const geometry::CameraModel* model = geometry::FindCameraModel(ref.image->metadata());
            if (model == nullptr) return py::none();
            return py::cast(*model);
          },
          "The saccade.geometry.CameraModel of the image as it is (K and distortion), or None.")
      .def_property_readonly(
          "X_WC",
          [](const ImageRef& ref) -> py::object {
            const geometry::Pose* pose = geometry::FindCameraPose(ref.image->metadata());
            if (pose == nullptr) return py::none();
            return py::cast(PoseToMatrix(*pose));
          },
          "The camera's optical frame in the world (4x4) when the image was taken, or None.")
      .def("__repr__", [](const ImageRef& ref) {
        return "<saccade.Image " + ref.image->metadata().camera + " " +
               std::to_string(ref.image->width()) + "x" + std::to_string(ref.image->height()) +
               " " + ToString(ref.image->format()) + ">";
      });
}

}  // namespace saccade::python
