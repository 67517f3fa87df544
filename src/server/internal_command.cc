#include "server/internal_command.h"

#include <algorithm>
#include <limits>

namespace saccade::server::internal_gui {

using nlohmann::json;

int NestingDepth(std::string_view text) {
  int depth = 0;
  int deepest = 0;
  bool in_string = false;
  bool escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

ParsedCommand ParseCommand(std::string_view text, std::optional<int64_t> last_id) {
  ParsedCommand out;
  const auto fail = [&out](json id, std::string message) {
    out.command = nullptr;
    out.error_id = std::move(id);
    out.error = std::move(message);
    return out;
  };
  if (const int depth = NestingDepth(text); depth > kMaxNesting) {
    return fail(nullptr, "malformed JSON: nested " + std::to_string(depth) +
                             " levels deep, at most " + std::to_string(kMaxNesting));
  }
  json command;
  try {
    command = json::parse(text);
  } catch (const json::exception& e) {
    return fail(nullptr, std::string("malformed JSON: ") + e.what());
  }
  if (!command.is_object()) {
    return fail(nullptr, "a command must be a JSON object, got " + JsonTypeName(command));
  }
  // The id, when there is a valid one, goes into every error below.
  json id = nullptr;
  const auto id_it = command.find("id");
  const bool id_ok =
      id_it != command.end() && id_it->is_number_integer() &&
      !(id_it->is_number_unsigned() &&
        id_it->get<uint64_t>() > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()));
  if (id_ok) id = id_it->get<int64_t>();
  const auto type_it = command.find("type");
  if (type_it == command.end()) {
    return fail(id, "missing field 'type' (a string naming the command)");
  }
  if (!type_it->is_string()) {
    return fail(id, "field 'type' must be a string, got " + JsonTypeName(*type_it));
  }
  if (id_it == command.end()) {
    return fail(nullptr, "missing field 'id' (an integer that grows with each command)");
  }
  if (!id_ok) {
    return fail(nullptr, "field 'id' must be an integer (int64), got " +
                             (id_it->is_number_integer() ? std::string("an out-of-range number")
                                                         : JsonTypeName(*id_it)));
  }
  const int64_t id_value = id.get<int64_t>();
  if (last_id && id_value <= *last_id) {
    return fail(
        id, "out of order: id " + std::to_string(id_value) + " after " + std::to_string(*last_id));
  }
  out.command = std::move(command);
  out.id = id_value;
  return out;
}

}  // namespace saccade::server::internal_gui
