#pragma once
// Private: saccade::Image <-> cv::Mat without copies where possible.
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "saccade/core/error.h"
#include "saccade/core/image.h"

namespace saccade::vision::internal {

/// A cv::Mat header over an RGB8, RGBA8 or Gray8 image's pixels (no copy; valid while `image`
/// lives). Throws InvalidArgument naming `who` and the format for any other format.
inline cv::Mat WrapMat(const Image& image, const char* who) {
  int type = 0;
  switch (image.format()) {
    case PixelFormat::kRgb8:
      type = CV_8UC3;
      break;
    case PixelFormat::kRgba8:
      type = CV_8UC4;
      break;
    case PixelFormat::kGray8:
      type = CV_8UC1;
      break;
    default:
      throw InvalidArgument(std::string(who) + ": image format " + ToString(image.format()) +
                            ", expected rgb8, rgba8 or gray8");
  }
  if (image.empty()) {
    throw InvalidArgument(std::string(who) + ": empty image, expected at least 1 x 1 pixels");
  }
  return cv::Mat(image.height(), image.width(), type, const_cast<uint8_t*>(image.data()),
                 image.stride());
}

/// A new Image of `like`'s format and metadata holding `mat`'s pixels (copied once).
inline Image ToImage(const cv::Mat& mat, const Image& like) {
  Image out(mat.cols, mat.rows, like.format());
  cv::Mat dst(out.height(), out.width(), mat.type(), out.data(), out.stride());
  mat.copyTo(dst);
  out.metadata() = like.metadata();
  return out;
}

/// Gray8 version of an RGB8 or Gray8 image (a header when already gray).
inline cv::Mat ToGray(const Image& image, const char* who) {
  const cv::Mat mat = WrapMat(image, who);
  if (mat.channels() == 1) return mat;
  cv::Mat gray;
  cv::cvtColor(mat, gray, mat.channels() == 4 ? cv::COLOR_RGBA2GRAY : cv::COLOR_RGB2GRAY);
  return gray;
}

}  // namespace saccade::vision::internal
