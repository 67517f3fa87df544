#pragma once
// The envelope of a command from a WebSocket client (docs/gui-protocol.md, "Commands"): text
// that must be a JSON object with a string `type` and an integer `id` that grows with each
// command. Kept apart from the session (no Boost here) so that the fuzzer
// (fuzz/command_fuzzer.cc) and the unit tests reach it without a socket.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace saccade::server::internal_gui {

// Commands nest a few levels; deeper input is refused before parsing, so that no handler
// walks (or dumps) it recursively.
inline constexpr int kMaxNesting = 64;

// The deepest nesting of arrays and objects in JSON text (strings skipped).
int NestingDepth(std::string_view text);

// "object", "array", "string", "number", ... for messages.
inline std::string JsonTypeName(const nlohmann::json& value) { return value.type_name(); }

// A command's text, checked: either `error` is empty and `command` is the object with its
// `id`, or `error` says what is wrong and `error_id` is the id to answer with (null when the
// text has no valid id).
struct ParsedCommand {
  nlohmann::json command;
  int64_t id = 0;
  std::string error;
  nlohmann::json error_id;
  bool ok() const { return error.empty(); }
};

// Checks one command's text: nesting depth, JSON syntax, an object, `type` a string, `id` an
// int64 greater than `last_id` (the previous accepted command's, if any). Never throws for
// bad text.
ParsedCommand ParseCommand(std::string_view text, std::optional<int64_t> last_id);

}  // namespace saccade::server::internal_gui
