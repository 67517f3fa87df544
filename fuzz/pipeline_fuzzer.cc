// libFuzzer target: pipeline YAML text -> runtime::ParsePipeline (and the hardware file it
// names, if any), then runtime::Pipeline::Build with the fuzzers' own small components
// (fuzz_pipeline_common.h): typed ports, declared parameters, required inputs, cycles. Bad
// input must end in a saccade::Error; anything else escaping -- another exception, a crash, a
// sanitizer report, a hang -- is a bug. What parses must hold what the format promises (names
// unique and well-formed, at most kMaxComponents, every component typed, delays 0 or 1,
// threads in range), and parsing the same text again gives the same spec. Built and run by
// fuzz/run.sh.
//
// The source is named pipelines/fuzz.yaml (the repository root is the working directory), so
// that a seed's `hardware: hardware/simulator.yaml` reads the committed hardware files.

#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_pipeline_common.h"
#include "saccade/core/error.h"

namespace {

constexpr std::size_t kMaxInput = 16 * 1024;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  using namespace saccade_fuzz;
  if (size > kMaxInput) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string source = "pipelines/fuzz.yaml";
  rt::PipelineSpec spec;
  try {
    spec = rt::ParsePipeline(text, source);
  } catch (const saccade::Error&) {
    return 0;  // rejected with a message: the expected outcome for bad input
  }
  CheckSpec(spec);
  CheckSameSpec(spec, rt::ParsePipeline(text, source));
  CheckBuild(spec);
  return 0;
}
