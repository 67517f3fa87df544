#pragma once
// JSON codecs (core/json_codec.h) of the image-plane types: a box [x, y, width, height] in
// whole pixels (x, y of the top-left pixel), a point [x, y] in pixels.
#include <cmath>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "saccade/core/json_codec.h"

namespace saccade {

template <>
struct JsonCodec<cv::Rect> {
  static nlohmann::json Encode(const cv::Rect& r) { return {r.x, r.y, r.width, r.height}; }
  static cv::Rect Decode(const nlohmann::json& j, const JsonWhere& at) {
    const char* what = "[x, y, width, height] in whole pixels, width and height >= 0";
    if (!j.is_array() || j.size() != 4) at.Fail(j, what);
    int v[4];
    for (std::size_t i = 0; i < 4; ++i) {
      // Whole numbers within int's range (a cast of anything else is undefined).
      if (!j[i].is_number() || !(std::abs(j[i].get<double>()) < 2147483647.0) ||
          j[i].get<double>() != std::floor(j[i].get<double>())) {
        at.Fail(j, what);
      }
      v[i] = static_cast<int>(j[i].get<double>());
    }
    if (v[2] < 0 || v[3] < 0) at.Fail(j, what);
    return {v[0], v[1], v[2], v[3]};
  }
};

template <>
struct JsonCodec<cv::Point2d> {
  static nlohmann::json Encode(const cv::Point2d& p) { return {p.x, p.y}; }
  static cv::Point2d Decode(const nlohmann::json& j, const JsonWhere& at) {
    if (!j.is_array() || j.size() != 2 || !j[0].is_number() || !j[1].is_number()) {
      at.Fail(j, "an array of 2 numbers");
    }
    return {j[0].get<double>(), j[1].get<double>()};
  }
};

}  // namespace saccade
