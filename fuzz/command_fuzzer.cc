// libFuzzer target: the GUI protocol's command envelope (docs/gui-protocol.md, "Commands";
// server/internal_command.h), what the WebSocket session checks before a command reaches
// its handler. The input is a series of messages from one client, separated by newlines,
// each checked against the id of the last one accepted, as the session does. Never a crash
// or an exception; an accepted command is a JSON object with a string `type` and an `id`
// above the last accepted one, nested at most kMaxNesting deep, whose text parses again to
// the same value; a refused one has a message, and its reply id is null or the command's
// own valid id. Built and run by fuzz/run.sh.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string_view>

#include "server/internal_command.h"

namespace gui = saccade::server::internal_gui;
using nlohmann::json;

namespace {

void Check(bool condition) {
  if (!condition) std::abort();  // libFuzzer reports it with the input
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return 0;
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  std::optional<int64_t> last_id;
  while (!rest.empty()) {
    const std::size_t end = rest.find('\n');
    const std::string_view text = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    const gui::ParsedCommand parsed = gui::ParseCommand(text, last_id);
    if (parsed.ok()) {
      Check(parsed.command.is_object());
      Check(parsed.command.at("type").is_string());
      Check(parsed.command.at("id").is_number_integer() &&
            parsed.command.at("id").get<int64_t>() == parsed.id);
      Check(!last_id || parsed.id > *last_id);
      Check(gui::NestingDepth(text) <= gui::kMaxNesting);
      // What a handler may dump and a client parse again is the same value.
      const std::string dumped =
          parsed.command.dump(-1, ' ', false, json::error_handler_t::replace);
      Check(gui::NestingDepth(dumped) <= gui::kMaxNesting);
      Check(json::parse(dumped) == parsed.command || dumped.find("\\ufffd") != std::string::npos);
      last_id = parsed.id;
    } else {
      Check(!parsed.error.empty());
      Check(parsed.command.is_null());
      Check(parsed.error_id.is_null() || parsed.error_id.is_number_integer());
    }
  }
  return 0;
}
