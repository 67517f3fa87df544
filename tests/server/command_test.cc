// The command envelope (server/internal_command.h): what the WebSocket session checks before
// a command reaches its handler. The same function the fuzzer (fuzz/command_fuzzer.cc) runs.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "server/internal_command.h"

namespace saccade::server::internal_gui {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

TEST(ParseCommand, AcceptsAnObjectWithTypeAndAGrowingId) {
  const ParsedCommand parsed = ParseCommand(R"({"type": "ping", "id": 7})", std::nullopt);
  ASSERT_TRUE(parsed.ok()) << parsed.error;
  EXPECT_EQ(parsed.id, 7);
  EXPECT_EQ(parsed.command["type"], "ping");
  EXPECT_TRUE(ParseCommand(R"({"type": "ping", "id": 8})", 7).ok());
}

TEST(ParseCommand, NamesWhatIsWrongAndKeepsAValidIdForTheReply) {
  struct Case {
    std::string text;
    std::optional<int64_t> last_id;
    std::string expected;
    json error_id;
  };
  const std::vector<Case> cases = {
      {"{", std::nullopt, "malformed JSON", nullptr},
      {"[1, 2]", std::nullopt, "a command must be a JSON object, got array", nullptr},
      {R"({"id": 3})", std::nullopt, "missing field 'type'", 3},
      {R"({"type": 5, "id": 3})", std::nullopt, "field 'type' must be a string, got number", 3},
      {R"({"type": "ping"})", std::nullopt, "missing field 'id'", nullptr},
      {R"({"type": "ping", "id": "3"})", std::nullopt,
       "field 'id' must be an integer (int64), "
       "got string",
       nullptr},
      {R"({"type": "ping", "id": 9223372036854775808})", std::nullopt, "got an out-of-range number",
       nullptr},
      {R"({"type": "ping", "id": 1.5})", std::nullopt, "got number", nullptr},
      {R"({"type": "ping", "id": 4})", 4, "out of order: id 4 after 4", 4},
      {std::string(65, '[') + std::string(65, ']'), std::nullopt,
       "nested 65 levels deep, at most 64", nullptr},
  };
  for (const Case& c : cases) {
    const ParsedCommand parsed = ParseCommand(c.text, c.last_id);
    EXPECT_FALSE(parsed.ok()) << c.text;
    EXPECT_THAT(parsed.error, HasSubstr(c.expected)) << c.text;
    EXPECT_EQ(parsed.error_id, c.error_id) << c.text;
  }
}

TEST(NestingDepth, SkipsBracketsInsideStrings) {
  EXPECT_EQ(NestingDepth(R"({"a": [[1]], "b": "[[[[\"{{"})"), 3);
  EXPECT_EQ(NestingDepth("plain"), 0);
}

}  // namespace
}  // namespace saccade::server::internal_gui
