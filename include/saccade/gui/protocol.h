#pragma once
// The GUI protocol declared once (docs/gui-protocol.md, issue 46): every message each way, its
// fields, their JSON types, ranges and meaning, as data. From this table
// - the session checks every command before it acts on it (a command that breaks it gets an
//   error reply naming the message and the field: "step: field 'count' must be in [1, 1000],
//   got 5000") and every message it writes;
// - `saccade gui --protocol-markdown` writes docs/gui-protocol.md and `--protocol-js` the page's
//   web/public/app/protocol.js, which checks what the page receives with the same rules and
//   the same words (web/public/app/schema.js); tests fail when either file and the table differ.
//
// The rules (CheckValue): a value must be of its schema's kind (null only where the schema
// says so); numbers are finite and within their range; strings one of their values, when
// listed; arrays of their length; objects carry every required field and, unless open, no
// other. The first problem found is the one reported, fields in their declared order, then
// unknown fields in name order.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace saccade::gui::protocol {

/// A JSON value's kind, as a schema requires it. kAny: anything (null included).
enum class Kind { kAny, kBoolean, kInteger, kNumber, kString, kArray, kObject };

struct Field;

/// What a JSON value must be. Made with the functions below (Number(), Object({...}), ...).
struct Schema {
  Kind kind = Kind::kAny;
  /// A named type ("pose"): the docs and protocol.js define it once and refer to it.
  std::string name;
  bool nullable = false;
  std::optional<nlohmann::json> constant;  ///< the one value allowed
  std::optional<double> min, max;          ///< numbers and integers, inclusive
  std::vector<std::string> values;         ///< strings: the values allowed; empty: any
  /// Arrays: one schema for every item, or (two or more) one per item, a tuple of that length.
  std::vector<Schema> items;
  std::optional<std::size_t> length;  ///< arrays: exactly this many items
  std::vector<Field> fields;          ///< objects: the fields, in order
  bool open = false;                  ///< objects: fields besides `fields` are allowed
  /// Open objects: what the other fields are ("a joint (scene.head.joints)"), for messages and
  /// docs; `items[0]`, when given, is what each of their values must be.
  std::string others;
  bool some = false;  ///< objects: at least one field
};

/// A field of an object: its name, what its value must be, whether it must be there, and one
/// line saying what it is (with its unit).
struct Field {
  std::string name;
  Schema schema;
  bool required = true;
  std::string doc;
};

// The schemas' makers.
Schema Any();
Schema Boolean();
Schema Integer(std::optional<double> min = std::nullopt, std::optional<double> max = std::nullopt);
Schema Number(std::optional<double> min = std::nullopt, std::optional<double> max = std::nullopt);
Schema String(std::vector<std::string> values = {});
/// Exactly `value` ("state", 2, true).
Schema Const(nlohmann::json value);
/// Items of one schema; `length`: exactly that many.
Schema Array(Schema item, std::optional<std::size_t> length = std::nullopt);
/// One schema per item.
Schema Tuple(std::vector<Schema> items);
Schema Object(std::vector<Field> fields);
/// `schema`, null allowed too.
Schema OrNull(Schema schema);
/// `schema` under a name of the protocol's types.
Schema Named(std::string name, Schema schema);
/// A required field.
Field Required(std::string name, Schema schema, std::string doc);
/// A field that may be missing.
Field Optional(std::string name, Schema schema, std::string doc);

/// The `map` message's bounds: at most this many points (a larger map sends every k-th voxel),
/// and at most one map every this many steps (only when the map changed).
inline constexpr int kMaxMapPoints = 50000;
inline constexpr int kMapEverySteps = 5;

/// Which way a message goes, and how.
enum class Channel {
  kCommand,   ///< client to server, WebSocket text: {"type", "id", ...}
  kText,      ///< server to client, WebSocket text
  kFrame,     ///< server to client, WebSocket binary: the JSON header of a camera frame
  kDocument,  ///< server to client, HTTP GET (the scene)
};

/// One message of the protocol.
struct Message {
  std::string type;  ///< its "type" ("joints", "state"; "scene" for /api/scene)
  Channel channel = Channel::kText;
  std::string summary;  ///< one line: what it does or says
  std::string doc;      ///< more, in Markdown (may be empty)
  Schema body;          ///< the whole message, an object ("type" and "id" included)
  /// Commands: the fields their reply adds to {"type": "reply", "id", "ok": true}.
  std::vector<Field> reply;
  /// Commands answered by the server module itself (flow control), not by the session.
  bool transport = false;
};

/// Every message, commands first, in the docs' order.
const std::vector<Message>& Messages();
/// The protocol's named types (pose, point, ...), each with a line saying what it is.
struct NamedType {
  Schema schema;
  std::string doc;
};
const std::vector<NamedType>& Types();

/// The message of `channel` and `type`, nullptr when there is none.
const Message* Find(Channel channel, std::string_view type);

/// The first problem of `value` against `schema`, "" when there is none: "field 'p_W[1]'
/// must be a number, got string". `path` names `value` ("" for a whole message).
std::string CheckValue(const Schema& schema, const nlohmann::json& value, const std::string& path);

/// A command (an object with a string "type"): "" when it is well formed, else its type and
/// the problem ("joints: field 'positions.pan' must be a number, got string"; "unknown
/// command type 'fly' (joints, ...)").
std::string CheckCommand(const nlohmann::json& command);
/// A WebSocket text message of the server (hello, state, reply, error, event). A reply is
/// checked against the reply of `command` (its type) when given, else its envelope only.
std::string CheckServerMessage(const nlohmann::json& message, std::string_view command = {});
/// A camera frame's JSON header.
std::string CheckFrameHeader(const nlohmann::json& header);
/// The scene document (GET /api/scene).
std::string CheckSceneDocument(const nlohmann::json& scene);

/// docs/gui-protocol.md.
std::string Markdown();
/// web/public/app/protocol.js: the table as data, and the page's checks over it.
std::string JavaScript();
/// The table as JSON (what protocol.js holds): {"types": {...}, "messages": [...]}.
nlohmann::json TableJson();

}  // namespace saccade::gui::protocol
