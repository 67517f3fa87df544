#pragma once
// Sharpening (seed Fig. 2, pre-processing) by unsharp masking:
//   out = in + amount * (in - GaussianBlur(in, sigma)),  saturated to 0 .. 255,
// so a step edge's contrast across it grows by a factor (1 + amount) right at the edge.
#include <string>

#include "saccade/core/image.h"
#include "saccade/core/interval.h"

namespace saccade::vision {

/// Unsharp mask. Thread-safe (Apply is const).
class Sharpener {
 public:
  struct Options {
    /// Gain of the detail (in - blur): kAmounts; 0 leaves the image unchanged.
    double amount = 1.0;
    /// Standard deviation of the Gaussian blur, pixels: kSigmas.
    double sigma = 1.0;

    // The valid values, stated once: IsValid checks them, and vision.sharpen declares its
    // parameters with them (runtime::ParamDecl::Range(const Interval&)). A gain above 100
    // saturates every pixel off a flat area.
    static constexpr Interval kAmounts = Interval::Closed(0, 100);
    static constexpr Interval kSigmas = Interval::LeftOpen(0, 50);

    bool IsValid(std::string* error) const;
  };

  /// Throws InvalidArgument with IsValid's message.
  Sharpener();  ///< default Options
  explicit Sharpener(const Options& options);

  /// The sharpened image (same size, format and metadata); borders reflect. `image` must be
  /// rgb8, rgba8 or gray8; throws InvalidArgument otherwise.
  Image Apply(const Image& image) const;

 private:
  Options options_;
};

}  // namespace saccade::vision
