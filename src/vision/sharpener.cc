#include "saccade/vision/sharpener.h"

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "internal_cv.h"
#include "saccade/core/error.h"

namespace saccade::vision {

bool Sharpener::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kAmounts.Contains(amount)) {
    what = kAmounts.Refusal("amount", amount);
  } else if (!kSigmas.Contains(sigma)) {
    what = kSigmas.Refusal("sigma", sigma);
  }
  if (what.empty()) return true;
  if (error) *error = "Sharpener::Options: " + what;
  return false;
}

Sharpener::Sharpener() : Sharpener(Options()) {}

Sharpener::Sharpener(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
}

Image Sharpener::Apply(const Image& image) const {
  const cv::Mat src = internal::WrapMat(image, "Sharpener::Apply");
  cv::Mat blurred;
  cv::GaussianBlur(src, blurred, cv::Size(0, 0), options_.sigma, options_.sigma,
                   cv::BORDER_REFLECT101);
  // in + a (in - blur) = (1 + a) in - a blur, in float then saturated back to 8 bits.
  cv::Mat dst;
  cv::addWeighted(src, 1.0 + options_.amount, blurred, -options_.amount, 0.0, dst, CV_8U);
  return internal::ToImage(dst, image);
}

}  // namespace saccade::vision
