#pragma once
// JSON codecs (core/json_codec.h) of geometry's value types: a point or vector [x, y, z]; a
// pose as its 4x4 matrix, row by row ([[r00, r01, r02, x], ..., [0, 0, 0, 1]]).
#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "saccade/core/json_codec.h"
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

}  // namespace saccade
