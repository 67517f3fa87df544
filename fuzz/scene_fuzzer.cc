// libFuzzer target: scene YAML text -> Scene::FromYamlString. Bad input must end in a
// saccade::Error (a FileError naming file, line and key); anything else escaping -- another
// exception, a crash, a sanitizer report, a hang -- is a bug. Built and run by fuzz/run.sh.
//
// Relative paths in the input resolve against $SACCADE_FUZZ_BASE_DIR (default "scenes", with
// the repository root as the working directory), so that seeds can name the head description
// (../robots/popeye.yaml) and small assets.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "saccade/core/error.h"
#include "saccade/scene/scene.h"

namespace {

// Scene files are small; longer inputs only slow the search down.
constexpr std::size_t kMaxInput = 16 * 1024;

const std::filesystem::path& BaseDir() {
  static const std::filesystem::path dir = [] {
    const char* env = std::getenv("SACCADE_FUZZ_BASE_DIR");
    return std::filesystem::path(env != nullptr ? env : "scenes");
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size > kMaxInput) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const saccade::scene::Scene scene =
        saccade::scene::Scene::FromYamlString(text, "fuzz.yaml", BaseDir());
    // Touch what a renderer would: poses of every object and camera at a few times.
    saccade::scene::SceneState state = scene.InitialState();
    for (const double t : {0.0, 0.7, -3.0, 1e6}) {
      state.time = t;
      for (const auto& object : scene.objects()) (void)scene.ObjectPose(object, state);
      for (const auto& camera : scene.cameras()) (void)scene.CameraPose(camera, state);
    }
  } catch (const saccade::Error&) {
    // Rejected with a message: the expected outcome for bad input.
  }
  return 0;
}
