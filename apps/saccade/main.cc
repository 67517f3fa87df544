// saccade: the command-line program. Thin: every subcommand parses its options, calls the
// libraries and prints text for people or --json for scripts (docs/cli.md documents the JSON).

#include <cstdio>

#include "commands.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"

int main(int argc, char** argv) {
  CLI::App app{
      "saccade: simulator and human-robot interface for active-vision stereo robot heads.\n"
      "Frames: world z up; head base x forward, y left, z up; cameras x right, y down, z "
      "forward.\nJoint signs: pan > 0 looks left, tilt > 0 looks down, an eye > 0 turns left.",
      "saccade"};
  app.require_subcommand(1);
  app.set_version_flag("--version", SACCADE_VERSION);
  // The logger's level (core/log.h): before or after the subcommand.
  std::string log_level;
  app.add_option("--log-level", log_level,
                 "Least severe log lines shown on stderr: trace, debug, info, warn, error or off "
                 "(default info, or SACCADE_LOG_LEVEL)")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "warning", "error", "off"}));
  app.fallthrough();
  namespace a = saccade::app;
  const std::vector<std::pair<CLI::App*, a::Runner>> commands = [&] {
    std::vector<std::pair<CLI::App*, a::Runner>> list;
    for (auto add : {a::AddFkCommand, a::AddIkCommand, a::AddCameraCommand, a::AddRenderCommand,
                     a::AddBenchCommand, a::AddDemoCommand, a::AddGuiCommand, a::AddRunCommand}) {
      a::Runner run = add(app);
      list.emplace_back(app.get_subcommands([](CLI::App*) { return true; }).back(), std::move(run));
    }
    return list;
  }();
  CLI11_PARSE(app, argc, argv);
  if (!log_level.empty()) saccade::log::SetLevel(saccade::log::ParseLevel(log_level));
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
