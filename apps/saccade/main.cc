// saccade: the command-line program. Thin: every subcommand parses its options, calls the
// libraries and prints text for people or --json for scripts (docs/cli.md documents the JSON).
//
// Exit statuses (docs/cli.md, "Exit statuses"), the same for every subcommand: 0 done; 1 an
// error, with its message on stderr as "saccade: error: ...": bad input (an unknown
// subcommand or option, a value out of range, a file that cannot be read or is wrong) or a
// failure while running; 3 `saccade demo` fixated no face; 130 `saccade render` cut short by
// Ctrl-C.

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "commands.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"

namespace {

constexpr int kExitError = 1;

// The subcommands' names, comma-separated, for errors that must list them.
std::string SubcommandList(const CLI::App& app) {
  std::string names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    names += (names.empty() ? "" : ", ") + sub->get_name();
  }
  return names;
}

// Each subcommand on one line: its name and the first sentence of its description.
std::string SubcommandSummary(const CLI::App& app) {
  std::string text = "Subcommands (`saccade SUBCOMMAND --help` for each):\n";
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    std::string line = sub->get_description();
    const size_t end = std::min(line.find(": "), line.find(". "));
    if (end != std::string::npos) line.resize(end);
    if (!line.empty() && line.back() == '.') line.pop_back();
    char name[16];
    std::snprintf(name, sizeof(name), "  %-8s", sub->get_name().c_str());
    text += name + line + "\n";
  }
  return text;
}

// The first word that is neither an option nor an option's value: the subcommand the user
// meant. CLI11 would let `saccade wander --help` print the main help and exit 0; an unknown
// name is an error of its own.
const char* FirstWord(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--") == 0) return i + 1 < argc ? argv[i + 1] : nullptr;
    if (argv[i][0] != '-') return argv[i];
    if (std::strcmp(argv[i], "--log-level") == 0) ++i;  // its value
  }
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "saccade: simulator and human-robot interface for active-vision stereo robot heads.\n"
      "Frames: world z up; head base x forward, y left, z up; cameras x right, y down, z "
      "forward.\nJoint signs: pan > 0 looks left, tilt > 0 looks down, an eye > 0 turns left.\n"
      "Exit status: 0 done, 1 error (bad input or a failure; the message on stderr), 3 `demo` "
      "fixated no face, 130 `render` cut short by Ctrl-C.",
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
    for (auto add :
         {a::AddFkCommand, a::AddIkCommand, a::AddCameraCommand, a::AddRenderCommand,
          a::AddBenchCommand, a::AddDemoCommand, a::AddGuiCommand, a::AddRunCommand,
          a::AddUrdfCommand, a::AddMcapCommand, a::AddExploreCommand, a::AddEmvaCommand}) {
      a::Runner run = add(app);
      list.emplace_back(app.get_subcommands([](CLI::App*) { return true; }).back(), std::move(run));
    }
    return list;
  }();
  // Usage errors read as every other error: "saccade: error: ...", status 1.
  app.failure_message([](const CLI::App* top, const CLI::Error& e) {
    std::string sub;
    for (const CLI::App* s : top->get_subcommands([](const CLI::App* s) { return s->parsed(); })) {
      sub = s->get_name() + " ";
    }
    return "saccade: error: " + std::string(e.what()) + "\nRun `saccade " + sub +
           "--help` for more information.\n";
  });

  if (argc == 1) {  // no subcommand at all: say which there are, one line each
    std::fprintf(stderr, "Usage: saccade [--log-level LEVEL] SUBCOMMAND [OPTIONS]\n\n%s\n",
                 SubcommandSummary(app).c_str());
    std::fprintf(stderr, "saccade: error: a subcommand is required: %s\n",
                 SubcommandList(app).c_str());
    return kExitError;
  }
  if (const char* word = FirstWord(argc, argv); word != nullptr) {
    bool known = false;
    for (const auto& entry : commands) known = known || entry.first->get_name() == word;
    if (!known) {
      std::fprintf(stderr, "saccade: error: '%s' is not a subcommand; they are: %s\n", word,
                   SubcommandList(app).c_str());
      return kExitError;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 checks required options before unknown ones: `fk --jionts 1 2 3 4` would say
    // "--joints is required". The word the user mistyped is the better message.
    if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr && !app.remaining(true).empty()) {
      std::vector<std::string> extras = app.remaining(true);
      std::reverse(extras.begin(), extras.end());  // CLI11 keeps them last first
      return app.exit(CLI::ExtrasError(extras)) == 0 ? 0 : kExitError;
    }
    const int status = app.exit(e);  // --help and --version print and give 0
    return status == 0 ? 0 : kExitError;
  }
  try {
    if (!log_level.empty()) saccade::log::SetLevel(saccade::log::ParseLevel(log_level));
    for (const auto& [sub, run] : commands) {
      if (sub->parsed()) return run();
    }
  } catch (const saccade::Error& e) {
    std::fprintf(stderr, "saccade: error: %s\n", e.what());
    return kExitError;
  } catch (const std::exception& e) {
    // Not saccade's own error class (a library's, or memory): still a message and status 1,
    // never an abort.
    std::fprintf(stderr, "saccade: error: %s\n", e.what());
    return kExitError;
  }
  return 0;
}
