// saccade: the command-line program. Thin: every subcommand parses its options, calls the
// libraries and prints text for people or --json for scripts (README documents the JSON).

#include <cstdio>

#include "commands.h"
#include "saccade/core/error.h"

int main(int argc, char** argv) {
  CLI::App app{
      "saccade: simulator and human-robot interface for active-vision stereo robot heads.\n"
      "Frames: world z up; head base x forward, y left, z up; cameras x right, y down, z "
      "forward.\nJoint signs: pan > 0 looks left, tilt > 0 looks down, an eye > 0 turns left.",
      "saccade"};
  app.require_subcommand(1);
  app.set_version_flag("--version", SACCADE_VERSION);
  namespace a = saccade::app;
  const std::vector<std::pair<CLI::App*, a::Runner>> commands = [&] {
    std::vector<std::pair<CLI::App*, a::Runner>> list;
    for (auto add : {a::AddFkCommand, a::AddIkCommand, a::AddCameraCommand, a::AddRenderCommand,
                     a::AddBenchCommand, a::AddDemoCommand, a::AddGuiCommand}) {
      a::Runner run = add(app);
      list.emplace_back(app.get_subcommands([](CLI::App*) { return true; }).back(), std::move(run));
    }
    return list;
  }();
  CLI11_PARSE(app, argc, argv);
  try {
    for (const auto& [sub, run] : commands) {
      if (sub->parsed()) return run();
    }
  } catch (const saccade::Error& e) {
    std::fprintf(stderr, "saccade: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
