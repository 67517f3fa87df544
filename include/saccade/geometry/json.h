#pragma once
// JSON codecs (core/json_codec.h) of geometry's value types: a point or vector [x, y, z]; a
// pose as its 4x4 matrix, row by row ([[r00, r01, r02, x], ..., [0, 0, 0, 1]]); a camera
// model as {"width", "height", "K": 3x3 row by row, "distortion": {"model": "none|radtan|
// fisheye", "coefficients": [...]}} (frames.jsonl, the GUI's scene document).
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "saccade/core/error.h"
#include "saccade/core/json_codec.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"

namespace saccade {

template <>
struct JsonCodec<Eigen::Vector3d> {
  static nlohmann::json Encode(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
  static Eigen::Vector3d Decode(const nlohmann::json& j, const JsonWhere& at) {
    if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() ||
        !j[2].is_number()) {
      at.Fail(j, "an array of 3 numbers");
    }
    return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
  }
};

template <>
struct JsonCodec<geometry::Pose> {
  static nlohmann::json Encode(const geometry::Pose& X) {
    nlohmann::json out = nlohmann::json::array();
    for (int r = 0; r < 4; ++r) out.push_back({X(r, 0), X(r, 1), X(r, 2), X(r, 3)});
    return out;
  }
  /// The last row must be [0, 0, 0, 1]; the rotation is taken as given.
  static geometry::Pose Decode(const nlohmann::json& j, const JsonWhere& at) {
    const char* what = "a 4x4 matrix, row by row, last row [0, 0, 0, 1]";
    if (!j.is_array() || j.size() != 4) at.Fail(j, what);
    Eigen::Matrix4d m;
    for (int r = 0; r < 4; ++r) {
      const nlohmann::json& row = j[static_cast<std::size_t>(r)];
      if (!row.is_array() || row.size() != 4) at.Fail(j, what);
      for (int c = 0; c < 4; ++c) {
        const nlohmann::json& x = row[static_cast<std::size_t>(c)];
        if (!x.is_number()) at.Fail(j, what);
        m(r, c) = x.get<double>();
      }
    }
    if (m(3, 0) != 0.0 || m(3, 1) != 0.0 || m(3, 2) != 0.0 || m(3, 3) != 1.0) at.Fail(j, what);
    geometry::Pose X = geometry::Pose::Identity();
    X.matrix() = m;
    return X;
  }
};

template <>
struct JsonCodec<geometry::CameraModel> {
  static nlohmann::json Encode(const geometry::CameraModel& model) {
    const geometry::Intrinsics& k = model.intrinsics();
    const Eigen::Matrix3d K = k.Matrix();
    nlohmann::json rows = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) rows.push_back({K(r, 0), K(r, 1), K(r, 2)});
    return {{"width", k.width()},
            {"height", k.height()},
            {"K", rows},
            {"distortion",
             {{"model", geometry::ToString(model.distortion().model())},
              {"coefficients", model.distortion().coefficients()}}}};
  }
  /// Checks what the camera model's own constructors check (sizes, K's form, coefficients).
  static geometry::CameraModel Decode(const nlohmann::json& j, const JsonWhere& at) {
    const char* what =
        "{width, height, K: 3x3, distortion: {model: none|radtan|fisheye, coefficients}}";
    if (!j.is_object() || !j.contains("width") || !j.contains("height") || !j.contains("K") ||
        !j["width"].is_number_integer() || !j["height"].is_number_integer() || !j["K"].is_array() ||
        j["K"].size() != 3) {
      at.Fail(j, what);
    }
    Eigen::Matrix3d K;
    for (int r = 0; r < 3; ++r) {
      const nlohmann::json& row = j["K"][static_cast<std::size_t>(r)];
      if (!row.is_array() || row.size() != 3) at.Fail(j, what);
      for (int c = 0; c < 3; ++c) {
        if (!row[static_cast<std::size_t>(c)].is_number()) at.Fail(j, what);
        K(r, c) = row[static_cast<std::size_t>(c)].get<double>();
      }
    }
    geometry::DistortionModel model = geometry::DistortionModel::kNone;
    std::vector<double> coefficients;
    if (j.contains("distortion")) {
      const nlohmann::json& d = j["distortion"];
      if (!d.is_object() || !d.contains("model") || !d["model"].is_string()) at.Fail(j, what);
      const std::string name = d["model"].get<std::string>();
      if (name == "radtan") {
        model = geometry::DistortionModel::kRadialTangential;
      } else if (name == "fisheye") {
        model = geometry::DistortionModel::kFisheye;
      } else if (name != "none") {
        at.Fail(j, what);
      }
      if (d.contains("coefficients")) {
        if (!d["coefficients"].is_array()) at.Fail(j, what);
        for (const nlohmann::json& c : d["coefficients"]) {
          if (!c.is_number()) at.Fail(j, what);
          coefficients.push_back(c.get<double>());
        }
      }
    }
    try {
      return geometry::CameraModel(
          geometry::Intrinsics::FromMatrix(K, j["width"].get<int>(), j["height"].get<int>()),
          geometry::Distortion::FromCoefficients(model, coefficients));
    } catch (const Error& e) {
      at.Fail(j, std::string(what) + " (" + e.what() + ")");
    }
  }
};

}  // namespace saccade
