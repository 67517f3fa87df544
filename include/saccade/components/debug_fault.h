#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "saccade/runtime/component.h"

namespace saccade::components {

/// debug.fault -- fault injection, to see how a pipeline and its tools handle a failing
/// component: throws saccade::Error(`message`) in its Step at step `at_step` (and, with
/// `every: true`, at every later step). No ports.
class DebugFault : public runtime::Component {
 public:
  DebugFault();
  void Step(const runtime::StepContext& context) override;

 private:
  int64_t at_step_ = 0;
  bool every_ = false;
  std::string message_ = "injected fault";
};

}  // namespace saccade::components
