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
#include "saccade/vision/undistorter.h"

namespace saccade::components {

class UndistortComponent : public ImageFilterComponent {
 public:
  UndistortComponent();

 protected:
  Image Apply(const Image& image) override;

 private:
  vision::Undistorter::Options options_;
  std::unique_ptr<vision::Undistorter> undistorter_;  // made for the latest camera seen
};

}  // namespace saccade::components
