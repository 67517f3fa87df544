// `saccade bench` without the application: the render benchmark (render/benchmark.h) in a
// binary that needs only the render module's libraries, not OpenCV's, so that it can be carried
// to a machine with a GPU and nothing installed, with those libraries beside it
// (LD_LIBRARY_PATH; bench/baselines/h100-nvidia-egl.md says how it ran on an H200).
//
//     render_bench [SCENE (scenes/bench.yaml)] [FRAMES (60)] [--json] [--no-effect-table]
#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>

#include "saccade/render/benchmark.h"
#include "saccade/scene/scene.h"

int main(int argc, char** argv) {
  std::string path = "scenes/bench.yaml";
  int frames = 60;
  bool json = false;
  bool effect_table = true;
  int positional = 0;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--json") {
      json = true;
    } else if (arg == "--no-effect-table") {
      effect_table = false;
    } else if (arg == "-h" || arg == "--help") {
      fmt::print(
          "usage: render_bench [SCENE (scenes/bench.yaml)] [FRAMES (60)] [--json] "
          "[--no-effect-table]\n");
      return 0;
    } else if (positional++ == 0) {
      path = arg;
    } else {
      frames = std::atoi(arg.c_str());
      if (frames < 1) {
        fmt::print(stderr, "render_bench: FRAMES must be a whole number >= 1, got '{}'\n", arg);
        return 2;
      }
    }
  }
  try {
    const saccade::scene::Scene scene = saccade::scene::Scene::Load(path);
    saccade::render::RendererOptions options;  // every effect the scene has, as saccade bench
    const saccade::render::BenchReport report = saccade::render::Bench(
        path, scene, options, frames, std::max(10, frames / 10), effect_table);
    if (json) {
      std::cout << report.Json().dump(2) << "\n";
    } else {
      fmt::print("{}", report.Text());
    }
  } catch (const std::exception& error) {
    fmt::print(stderr, "render_bench: {}\n", error.what());
    return 1;
  }
  return 0;
}
