#include "saccade/vision/median_filter.h"

#include <opencv2/imgproc.hpp>

#include "internal_cv.h"
#include "saccade/core/error.h"

namespace saccade::vision {

bool MedianFilter::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kKernelSizes.Contains(kernel_size)) {
    what = kKernelSizes.Refusal("kernel_size", kernel_size);
  } else if (kernel_size % 2 == 0) {
    what = "kernel_size " + std::to_string(kernel_size) + ", expected an odd number";
  }
  if (what.empty()) return true;
  if (error) *error = "MedianFilter::Options: " + what;
  return false;
}

MedianFilter::MedianFilter() : MedianFilter(Options()) {}

MedianFilter::MedianFilter(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
}

Image MedianFilter::Apply(const Image& image) const {
  const cv::Mat src = internal::WrapMat(image, "MedianFilter::Apply");
  cv::Mat dst;
  cv::medianBlur(src, dst, options_.kernel_size);
  return internal::ToImage(dst, image);
}

}  // namespace saccade::vision
