// The protocol's checks (protocol.h): the same rules and the same words as the page's
// (web/public/app/schema.js), so that a message refused on either side names the same field.
#include "saccade/gui/protocol.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace saccade::gui::protocol {
namespace {

using nlohmann::json;

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::string Where(const std::string& path) {
  return path.empty() ? std::string("the message") : "field '" + path + "'";
}

std::string Child(const std::string& path, const std::string& name) {
  return path.empty() ? name : path + "." + name;
}

// "a number", "an object or null": what the schema's kind is, for the messages.
std::string Expected(const Schema& schema) {
  std::string kind;
  switch (schema.kind) {
    case Kind::kAny:
      kind = "anything";
      break;
    case Kind::kBoolean:
      kind = "a boolean";
      break;
    case Kind::kInteger:
      kind = "an integer";
      break;
    case Kind::kNumber:
      kind = "a number";
      break;
    case Kind::kString:
      kind = "a string";
      break;
    case Kind::kArray:
      kind = "an array";
      break;
    case Kind::kObject:
      kind = "an object";
      break;
  }
  return schema.nullable ? kind + " or null" : kind;
}

bool OfKind(const json& value, Kind kind) {
  switch (kind) {
    case Kind::kAny:
      return true;
    case Kind::kBoolean:
      return value.is_boolean();
    case Kind::kInteger:
      return value.is_number_integer();
    case Kind::kNumber:
      return value.is_number();
    case Kind::kString:
      return value.is_string();
    case Kind::kArray:
      return value.is_array();
    case Kind::kObject:
      return value.is_object();
  }
  return false;
}

// A number as JavaScript's String(x) writes it (0.05, 10, 1000).
std::string NumberText(double x) { return fmt::format("{}", x); }

std::string CheckNumber(const Schema& schema, const json& value, const std::string& path) {
  const double x = value.get<double>();
  if (!std::isfinite(x)) return Where(path) + " must be a finite number";
  const bool low = schema.min && x < *schema.min;
  const bool high = schema.max && x > *schema.max;
  if (!low && !high) return "";
  if (schema.min && schema.max) {
    return fmt::format("{} must be in [{}, {}], got {}", Where(path), NumberText(*schema.min),
                       NumberText(*schema.max), value.dump());
  }
  return fmt::format("{} must be at {} {}, got {}", Where(path), low ? "least" : "most",
                     NumberText(low ? *schema.min : *schema.max), value.dump());
}

std::string CheckArray(const Schema& schema, const json& value, const std::string& path) {
  const bool tuple = schema.items.size() > 1;
  const std::optional<std::size_t> length = tuple ? schema.items.size() : schema.length;
  if (length && value.size() != *length) {
    return fmt::format("{} must have {} items, got {}", Where(path), *length, value.size());
  }
  for (std::size_t i = 0; i < value.size() && !schema.items.empty(); ++i) {
    const Schema& item = tuple ? schema.items[i] : schema.items[0];
    std::string problem = CheckValue(item, value[i], fmt::format("{}[{}]", path, i));
    if (!problem.empty()) return problem;
  }
  return "";
}

std::string CheckObject(const Schema& schema, const json& value, const std::string& path) {
  if (schema.some && value.empty()) {
    std::vector<std::string> names;
    for (const Field& f : schema.fields) names.push_back(f.name);
    std::string what = Join(names);
    if (!schema.others.empty()) what += (what.empty() ? "" : " or ") + schema.others;
    return Where(path) + " must name at least one of " + what;
  }
  for (const Field& f : schema.fields) {
    const auto it = value.find(f.name);
    if (it == value.end()) {
      if (f.required) return "missing field '" + Child(path, f.name) + "'";
      continue;
    }
    std::string problem = CheckValue(f.schema, *it, Child(path, f.name));
    if (!problem.empty()) return problem;
  }
  if (schema.open) {
    if (schema.items.empty()) return "";
    for (const auto& [key, item] : value.items()) {  // in name order (a std::map)
      const auto known = std::find_if(schema.fields.begin(), schema.fields.end(),
                                      [&key](const Field& f) { return f.name == key; });
      if (known != schema.fields.end()) continue;
      std::string problem = CheckValue(schema.items[0], item, Child(path, key));
      if (!problem.empty()) return problem;
    }
    return "";
  }
  for (const auto& [key, unused] : value.items()) {  // in name order (a std::map)
    const auto known = std::find_if(schema.fields.begin(), schema.fields.end(),
                                    [&key](const Field& f) { return f.name == key; });
    if (known != schema.fields.end()) continue;
    std::vector<std::string> names;
    for (const Field& f : schema.fields) {
      if (!(path.empty() && (f.name == "type" || f.name == "id"))) names.push_back(f.name);
    }
    return "unknown field '" + Child(path, key) + "'" +
           (names.empty() ? std::string() : " (expected " + Join(names) + ")");
  }
  return "";
}

std::string Names(Channel channel) {
  std::vector<std::string> names;
  for (const Message& m : Messages()) {
    if (m.channel == channel) names.push_back(m.type);
  }
  return Join(names);
}

}  // namespace

Schema Any() { return Schema{}; }

Schema Boolean() {
  Schema s;
  s.kind = Kind::kBoolean;
  return s;
}

Schema Integer(std::optional<double> min, std::optional<double> max) {
  Schema s;
  s.kind = Kind::kInteger;
  s.min = min;
  s.max = max;
  return s;
}

Schema Number(std::optional<double> min, std::optional<double> max) {
  Schema s = Integer(min, max);
  s.kind = Kind::kNumber;
  return s;
}

Schema String(std::vector<std::string> values) {
  Schema s;
  s.kind = Kind::kString;
  s.values = std::move(values);
  return s;
}

Schema Const(json value) {
  Schema s;
  s.kind = value.is_boolean()          ? Kind::kBoolean
           : value.is_number_integer() ? Kind::kInteger
           : value.is_number()         ? Kind::kNumber
           : value.is_string()         ? Kind::kString
                                       : Kind::kAny;
  s.constant = std::move(value);
  return s;
}

Schema Array(Schema item, std::optional<std::size_t> length) {
  Schema s;
  s.kind = Kind::kArray;
  s.items.push_back(std::move(item));
  s.length = length;
  return s;
}

Schema Tuple(std::vector<Schema> items) {
  Schema s;
  s.kind = Kind::kArray;
  s.length = items.size();
  s.items = std::move(items);
  return s;
}

Schema Object(std::vector<Field> fields) {
  Schema s;
  s.kind = Kind::kObject;
  s.fields = std::move(fields);
  return s;
}

Schema OrNull(Schema schema) {
  schema.nullable = true;
  return schema;
}

Schema Named(std::string name, Schema schema) {
  schema.name = std::move(name);
  return schema;
}

Field Required(std::string name, Schema schema, std::string doc) {
  return Field{std::move(name), std::move(schema), true, std::move(doc)};
}

Field Optional(std::string name, Schema schema, std::string doc) {
  return Field{std::move(name), std::move(schema), false, std::move(doc)};
}

std::string CheckValue(const Schema& schema, const json& value, const std::string& path) {
  if (schema.kind == Kind::kAny || (value.is_null() && schema.nullable)) return "";
  if (schema.constant) {
    if (value == *schema.constant) return "";
    return fmt::format("{} must be {}, got {}", Where(path), schema.constant->dump(),
                       value.is_structured() ? value.type_name() : value.dump());
  }
  if (!OfKind(value, schema.kind)) {
    return fmt::format("{} must be {}, got {}", Where(path), Expected(schema),
                       value.is_number() ? value.dump() : value.type_name());
  }
  switch (schema.kind) {
    case Kind::kInteger:
    case Kind::kNumber:
      return CheckNumber(schema, value, path);
    case Kind::kString:
      if (schema.values.empty() || std::find(schema.values.begin(), schema.values.end(),
                                             value.get<std::string>()) != schema.values.end()) {
        return "";
      }
      return fmt::format("{} must be one of {}, got {}", Where(path), Join(schema.values),
                         value.dump());
    case Kind::kArray:
      return CheckArray(schema, value, path);
    case Kind::kObject:
      return CheckObject(schema, value, path);
    default:
      return "";
  }
}

const Message* Find(Channel channel, std::string_view type) {
  for (const Message& m : Messages()) {
    if (m.channel == channel && m.type == type) return &m;
  }
  return nullptr;
}

std::string CheckCommand(const json& command) {
  if (!command.is_object() || !command.contains("type") || !command["type"].is_string()) {
    return "a command must be an object with a string field 'type'";
  }
  const std::string type = command["type"].get<std::string>();
  const Message* m = Find(Channel::kCommand, type);
  if (m == nullptr) {
    return "unknown command type '" + type + "' (" + Names(Channel::kCommand) +
           ": docs/gui-protocol.md)";
  }
  const std::string problem = CheckValue(m->body, command, "");
  return problem.empty() ? "" : type + ": " + problem;
}

std::string CheckServerMessage(const json& message, std::string_view command) {
  if (!message.is_object() || !message.contains("type") || !message["type"].is_string()) {
    return "a message must be an object with a string field 'type'";
  }
  const std::string type = message["type"].get<std::string>();
  const Message* m = Find(Channel::kText, type);
  if (m == nullptr) {
    return "unknown message type '" + type + "' (" + Names(Channel::kText) + ")";
  }
  if (type != "reply") {
    const std::string problem = CheckValue(m->body, message, "");
    return problem.empty() ? "" : type + ": " + problem;
  }
  // A reply: its envelope and the fields of its command's reply.
  Schema body = m->body;
  const Message* c = command.empty() ? nullptr : Find(Channel::kCommand, command);
  if (c == nullptr) {
    body.open = true;
  } else {
    body.fields.insert(body.fields.end(), c->reply.begin(), c->reply.end());
  }
  const std::string problem = CheckValue(body, message, "");
  if (problem.empty()) return "";
  return (c == nullptr ? std::string("reply: ") : "reply to " + c->type + ": ") + problem;
}

std::string CheckFrameHeader(const json& header) {
  const std::string problem = CheckValue(Find(Channel::kFrame, "frame")->body, header, "");
  return problem.empty() ? "" : "frame: " + problem;
}

std::string CheckSceneDocument(const json& scene) {
  const std::string problem = CheckValue(Find(Channel::kDocument, "scene")->body, scene, "");
  return problem.empty() ? "" : "scene: " + problem;
}

}  // namespace saccade::gui::protocol
