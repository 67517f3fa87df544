// libFuzzer target: a hardware file (the one line that swaps the simulated robot for the real
// one, runtime/pipeline.h) -> runtime::ParsePipeline with that file given as `hardware`, then
// Pipeline::Build with the fuzzers' own components (fuzz_pipeline_common.h). The input is the
// hardware file; when it holds a line "#pipeline", what follows that line is the pipeline file
// instead of the default one (components `cameras` and `head`, both typed by the hardware
// file). Bad input must end in a saccade::Error; anything else is a bug. What parses must
// hold the format's promises (fuzz_pipeline_common.h), and at least one component must have
// its type and params from the hardware file (params_file names it). Built and
// run by fuzz/run.sh.
//
// The hardware file is written to a file of its own ($TMPDIR or /tmp, per process), since
// ParsePipeline reads it by path; its relative paths resolve against that folder.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "fuzz_pipeline_common.h"
#include "saccade/core/error.h"

namespace {

constexpr std::size_t kMaxInput = 16 * 1024;
constexpr const char* kDefaultPipeline = R"(clock: {mode: simulated, step: 0.04, steps: 1}
components:
  - name: cameras
    inputs: {joints: {from: head.joints, delay: 1}}
  - name: head
)";

const std::string& HardwarePath() {
  static const std::string path = [] {
    const char* tmp = std::getenv("TMPDIR");
    const std::filesystem::path dir = tmp != nullptr ? tmp : "/tmp";
    return (dir / ("saccade-hardware-fuzz-" + std::to_string(getpid()) + ".yaml")).string();
  }();
  return path;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  using namespace saccade_fuzz;
  if (size > kMaxInput) return 0;
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::string hardware = input;
  std::string pipeline = kDefaultPipeline;
  if (const std::size_t at = input.find("#pipeline\n"); at != std::string::npos) {
    hardware = input.substr(0, at);
    pipeline = input.substr(at + 10);
  }
  {
    std::ofstream out(HardwarePath(), std::ios::binary | std::ios::trunc);
    out << hardware;
    Check(static_cast<bool>(out));
  }
  rt::PipelineSpec spec;
  try {
    spec = rt::ParsePipeline(pipeline, "pipelines/fuzz.yaml", HardwarePath());
  } catch (const saccade::Error&) {
    return 0;  // rejected with a message: the expected outcome for bad input
  }
  CheckSpec(spec);
  Check(spec.hardware_file == HardwarePath());
  // A hardware file defines at least one component, and the pipeline must have each: those
  // take their type and params from the file (params_file names it).
  std::size_t from_hardware = 0;
  for (const rt::ComponentSpec& c : spec.components) {
    from_hardware += c.params_file == HardwarePath();
  }
  Check(from_hardware >= 1);
  CheckSameSpec(spec, rt::ParsePipeline(pipeline, "pipelines/fuzz.yaml", HardwarePath()));
  CheckBuild(spec);
  return 0;
}
