#pragma once
// Median filter (seed Fig. 2, pre-processing): removes impulse ("salt and pepper") noise
// while keeping edges, per channel, with cv::medianBlur.
#include <string>

#include "saccade/core/image.h"
#include "saccade/core/interval.h"

namespace saccade::vision {

/// A square median filter. Thread-safe (Apply is const).
class MedianFilter {
 public:
  struct Options {
    /// Side of the square window, pixels: odd, in kKernelSizes (cv::medianBlur on 8-bit
    /// images).
    int kernel_size = 3;

    // The valid sizes, stated once: IsValid checks them (and that the size is odd), and
    // vision.median declares its parameter with them (runtime::ParamDecl::Range).
    static constexpr Interval kKernelSizes = Interval::Closed(3, 255);

    bool IsValid(std::string* error) const;
  };

  /// Throws InvalidArgument with IsValid's message.
  MedianFilter();  ///< default Options
  explicit MedianFilter(const Options& options);

  /// The filtered image (same size, format and metadata). Borders replicate the edge pixels.
  /// `image` must be rgb8, rgba8 or gray8; throws InvalidArgument otherwise.
  Image Apply(const Image& image) const;

 private:
  Options options_;
};

}  // namespace saccade::vision
