#include "saccade/components/debug_fault.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "components/internal_scene.h"
#include "saccade/core/error.h"

namespace saccade::components {

DebugFault::DebugFault() {
  DeclareParam("at_step", &at_step_, "the step at which Step throws").Min(0).Required();
  DeclareParam("message", &message_, "the error's message");
  DeclareParam("every", &every_, "throw at every later step too");
}

void DebugFault::Step(const runtime::StepContext& context) {
  if (context.step == at_step_ || (every_ && context.step > at_step_)) throw Error(message_);
}

}  // namespace saccade::components
