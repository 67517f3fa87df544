#pragma once
// vision.undistort / vision.median / vision.sharpen -- pre-processing (seed Fig. 2).
//   inputs: image (runtime.image, required); outputs: image (runtime.image), a new image with
//   the same metadata (undistort: distortion "none").
// Parameters: declared in the constructor (docs/components.md lists them).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/components/image_filter_component.h"
#include "saccade/vision/sharpener.h"

namespace saccade::components {

class SharpenComponent : public ImageFilterComponent {
 public:
  SharpenComponent();

 protected:
  void Configured() override;
  Image Apply(const Image& image) override { return filter_.Apply(image); }

 private:
  vision::Sharpener::Options options_;
  vision::Sharpener filter_;
};

}  // namespace saccade::components
