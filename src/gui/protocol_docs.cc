// What is generated from the protocol's table (protocol.h): docs/gui-protocol.md (the table's
// messages between the hand-written sections below) and web/public/app/protocol.js.
#include <fmt/format.h>

#include <cctype>
#include <string>
#include <vector>

#include "gui/internal_protocol_prose.h"
#include "saccade/gui/protocol.h"
#include "saccade/server/gui_server.h"

namespace saccade::gui::protocol {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

const char* KindName(Kind kind) {
  switch (kind) {
    case Kind::kAny:
      return "any";
    case Kind::kBoolean:
      return "boolean";
    case Kind::kInteger:
      return "integer";
    case Kind::kNumber:
      return "number";
    case Kind::kString:
      return "string";
    case Kind::kArray:
      return "array";
    case Kind::kObject:
      return "object";
  }
  return "any";
}

const char* ChannelName(Channel channel) {
  switch (channel) {
    case Channel::kCommand:
      return "command";
    case Channel::kText:
      return "text";
    case Channel::kFrame:
      return "frame";
    case Channel::kDocument:
      return "document";
  }
  return "text";
}

// ---- The table as JSON (protocol.js) ----

ordered_json SchemaJson(const Schema& s, bool define);

ordered_json FieldsJson(const std::vector<Field>& fields) {
  ordered_json out = ordered_json::array();
  for (const Field& f : fields) {
    out.push_back(
        {{"name", f.name}, {"required", f.required}, {"schema", SchemaJson(f.schema, false)}});
  }
  return out;
}

// `define`: the named type's definition itself, not a reference to it.
ordered_json SchemaJson(const Schema& s, bool define) {
  ordered_json out = ordered_json::object();
  if (!s.name.empty() && !define) {
    out["ref"] = s.name;
    if (s.nullable) out["nullable"] = true;
    return out;
  }
  out["kind"] = KindName(s.kind);
  if (s.nullable) out["nullable"] = true;
  if (s.constant) out["const"] = *s.constant;
  if (s.min) out["min"] = *s.min;
  if (s.max) out["max"] = *s.max;
  if (!s.values.empty()) out["values"] = s.values;
  if (!s.items.empty()) {
    out["items"] = ordered_json::array();
    for (const Schema& item : s.items) out["items"].push_back(SchemaJson(item, false));
  }
  if (s.length) out["length"] = *s.length;
  if (s.kind == Kind::kObject) out["fields"] = FieldsJson(s.fields);
  if (s.open) out["open"] = true;
  if (!s.others.empty()) out["others"] = s.others;
  if (s.some) out["some"] = true;
  return out;
}

ordered_json OrderedTable() {
  ordered_json types = ordered_json::object();
  for (const NamedType& t : Types()) types[t.schema.name] = SchemaJson(t.schema, true);
  ordered_json messages = ordered_json::array();
  for (const Message& m : Messages()) {
    ordered_json j = {
        {"type", m.type}, {"channel", ChannelName(m.channel)}, {"body", SchemaJson(m.body, true)}};
    if (m.channel == Channel::kCommand) j["reply"] = FieldsJson(m.reply);
    messages.push_back(j);
  }
  return {{"protocol", server::kProtocolName},
          {"version", server::kProtocolVersion},
          {"types", types},
          {"messages", messages}};
}

// JSON text, each value on one line when it fits in 100 columns at `indent`, else broken up.
std::string Pretty(const ordered_json& j, int indent) {
  const std::string flat = j.dump();
  if (!j.is_structured() || j.empty() || indent + flat.size() <= 100) return flat;
  const std::string pad(indent + 2, ' ');
  std::string out = j.is_object() ? "{\n" : "[\n";
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    out += first ? "" : ",\n";
    first = false;
    out += pad;
    if (j.is_object()) out += json(it.key()).dump() + ": ";
    out += Pretty(*it, indent + 2);
  }
  return out + "\n" + std::string(indent, ' ') + (j.is_object() ? "}" : "]");
}

// ---- Markdown ----

std::string FormatNumber(double x) { return fmt::format("{}", x); }

std::string Range(const Schema& s) {
  if (s.min && s.max) return " in [" + FormatNumber(*s.min) + ", " + FormatNumber(*s.max) + "]";
  if (s.min) return " ≥ " + FormatNumber(*s.min);
  if (s.max) return " ≤ " + FormatNumber(*s.max);
  return "";
}

// A schema in a few words: "integer 1...1000", "[`pose`](#types) or null".
std::string TypeText(const Schema& s) {
  std::string out;
  if (!s.name.empty()) {
    out = "[`" + s.name + "`](#types)";
  } else if (s.constant) {
    out = "`" + s.constant->dump() + "`";
  } else if (s.kind == Kind::kString && !s.values.empty()) {
    for (std::size_t i = 0; i < s.values.size(); ++i) {
      out += std::string(i == 0                     ? ""
                         : i + 1 == s.values.size() ? " or "
                                                    : ", ") +
             "`" + json(s.values[i]).dump() + "`";
    }
  } else if (s.kind == Kind::kArray && s.items.size() > 1) {
    for (const Schema& item : s.items) out += (out.empty() ? "" : ", ") + TypeText(item);
    out = "[" + out + "]";
  } else if (s.kind == Kind::kArray) {
    const std::string item = s.items.empty() ? "any" : TypeText(s.items[0]);
    const bool plural = !s.items.empty() && s.items[0].name.empty() && !s.items[0].constant &&
                        s.items[0].values.empty() && !s.items[0].min && !s.items[0].max;
    out = s.length ? fmt::format("{} × {}", item, *s.length)
                   : "array of " + item + (plural ? "s" : "");
  } else if (s.kind == Kind::kObject) {
    if (s.open && !s.others.empty()) {
      out = "object (" + s.others + (s.items.empty() ? "" : ": " + TypeText(s.items[0])) +
            (s.some ? ", at least one" : "") + ")";
    } else {
      out = s.open ? "object (any fields)" : s.some ? "object (at least one field)" : "object";
    }
  } else {
    out = std::string(KindName(s.kind)) + Range(s);
  }
  return s.nullable ? out + " or null" : out;
}

// The rows of a field table: `prefix` names the fields' parent ("joints.", "lights[].").
void FieldRows(const std::vector<Field>& fields, const std::string& prefix, std::string& out) {
  for (const Field& f : fields) {
    out += fmt::format("| `{}{}` | {}{} | {} |\n", prefix, f.name, TypeText(f.schema),
                       f.required ? "" : ", optional", f.doc);
    const Schema& s = f.schema;
    if (!s.name.empty()) continue;
    if (s.kind == Kind::kObject && !s.fields.empty()) {
      FieldRows(s.fields, prefix + f.name + ".", out);
    } else if (s.kind == Kind::kArray && s.items.size() == 1 && s.items[0].name.empty() &&
               s.items[0].kind == Kind::kObject) {
      FieldRows(s.items[0].fields, prefix + f.name + "[].", out);
    }
  }
}

std::string FieldTable(const std::vector<Field>& fields) {
  if (fields.empty()) return "No fields.\n";
  std::string out = "| field | type | meaning |\n|---|---|---|\n";
  FieldRows(fields, "", out);
  return out;
}

std::string MessageSection(const Message& m, const std::string& heading) {
  const std::string title = m.channel == Channel::kDocument ? "/api/" + m.type : m.type;
  std::string summary = m.summary;
  if (!summary.empty()) summary[0] = static_cast<char>(std::toupper(summary[0]));
  std::string out = fmt::format("{} `{}`\n{}.", heading, title, summary);
  if (!m.doc.empty()) out += " " + m.doc;
  out += "\n\n";
  if (m.channel != Channel::kCommand) return out + FieldTable(m.body.fields) + "\n";
  // A command's envelope (type, id) is said once, above.
  const std::vector<Field> fields(m.body.fields.begin() + 2, m.body.fields.end());
  out += FieldTable(fields);
  out += "\nIts reply's fields, besides `type`, `id` and `ok`:\n\n" + FieldTable(m.reply) + "\n";
  return out;
}

std::string TypesSection() {
  std::string out =
      "### Types\nThe fields below name these by name.\n\n| type | what |\n|---|---|\n";
  for (const NamedType& t : Types()) {
    out += fmt::format("| `{}` | {} |\n", t.schema.name, t.doc);
  }
  return out + "\n";
}

std::string CommandsSection() {
  std::string out = kCommandsProse;
  out += "| command | does |\n|---|---|\n";
  for (const Message& m : Messages()) {
    if (m.channel == Channel::kCommand)
      out += fmt::format("| [`{0}`](#{0}) | {1} |\n", m.type, m.summary);
  }
  out += "\n";
  for (const Message& m : Messages()) {
    if (m.channel == Channel::kCommand) out += MessageSection(m, "####");
  }
  return out;
}

}  // namespace

json TableJson() { return json::parse(OrderedTable().dump()); }

std::string Markdown() {
  std::string out = fmt::format("# The GUI protocol, version {0} (`{1}/{0}`)\n\n",
                                server::kProtocolVersion, server::kProtocolName);
  out += kIntroProse;
  out += kHttpProse;
  out += MessageSection(*Find(Channel::kDocument, "scene"), "###");
  out += kModelsProse;
  out += kWebSocketProse;
  out += TypesSection();
  out += "### Server to client\n";
  for (const Message& m : Messages()) {
    if (m.channel == Channel::kText) out += MessageSection(m, "####");
  }
  out += kFrameProse;
  out += MessageSection(*Find(Channel::kFrame, "frame"), "####");
  out += CommandsSection();
  out += kFlowProse;
  return out;
}

std::string JavaScript() {
  return std::string(kJsHeader) + "export const table = " + Pretty(OrderedTable(), 0) + ";\n\n" +
         kJsFooter;
}

}  // namespace saccade::gui::protocol
