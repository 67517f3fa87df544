#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/runtime/component.h"

namespace saccade::components {

/// Base of the image-to-image pre-processing components.
class ImageFilterComponent : public runtime::Component {
 public:
  ImageFilterComponent();
  void Step(const runtime::StepContext& context) override;

 protected:
  virtual Image Apply(const Image& image) = 0;

 private:
  runtime::Input<runtime::ImageMessage>& in_;
  runtime::Output<runtime::ImageMessage>& out_;
};

}  // namespace saccade::components
