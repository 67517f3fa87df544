#include "saccade/runtime/component_reference.h"

#include <fmt/format.h>

#include <algorithm>
#include <memory>

namespace saccade::runtime {
namespace {

std::string PortText(const PortReference& port, bool input) {
  return fmt::format("{} ({}{})", port.name, port.message_type,
                     input && port.required ? ", required" : "");
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

// "| a | b |" with the cell's pipes escaped.
std::string Cell(std::string text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += '\\';
    out += c;
  }
  return out;
}

}  // namespace

std::vector<ComponentReference> DescribeComponents(const ComponentRegistry& registry) {
  std::vector<ComponentReference> out;
  for (const std::string& type : registry.Types()) {
    const std::unique_ptr<Component> component = registry.Create(type);
    ComponentReference ref;
    ref.type = type;
    ref.description = registry.Description(type);
    for (const auto& in : component->inputs()) {
      ref.inputs.push_back({in->name(), in->message_type(), in->required()});
    }
    for (const auto& o : component->outputs())
      ref.outputs.push_back({o->name(), o->message_type()});
    for (const auto& m : component->methods()) {
      ref.methods.push_back({m->name(), m->request_type(), m->reply_type(), m->description()});
    }
    ref.params = component->param_table().infos();
    out.push_back(std::move(ref));
  }
  return out;
}

std::string ComponentsText(const std::vector<ComponentReference>& components) {
  std::string out;
  for (const ComponentReference& c : components) {
    out += fmt::format("{} -- {}\n", c.type, c.description);
    std::vector<std::string> ins, outs;
    for (const PortReference& p : c.inputs) ins.push_back(PortText(p, true));
    for (const PortReference& p : c.outputs) outs.push_back(PortText(p, false));
    if (!ins.empty()) out += "  inputs:  " + Join(ins) + "\n";
    if (!outs.empty()) out += "  outputs: " + Join(outs) + "\n";
    for (const MethodReference& m : c.methods) {
      out += fmt::format("  method {} ({} -> {}): {}\n", m.name, m.request_type, m.reply_type,
                         m.description);
    }
    std::size_t width = 0;
    for (const ParamInfo& p : c.params) width = std::max(width, p.name.size());
    if (!c.params.empty()) out += "  params:\n";
    for (const ParamInfo& p : c.params) {
      out += fmt::format("    {:<{}}  {}{}, {}{}: {}\n", p.name, width, p.TypeText(),
                         p.unit.empty() ? "" : " " + p.unit, p.required ? "" : "default ",
                         p.DefaultText(), p.doc);
    }
    out += "\n";
  }
  return out;
}

std::string ComponentsMarkdown(const std::vector<ComponentReference>& components) {
  std::string out =
      "# Components\n\n"
      "The component types a pipeline file can name ([formats](formats.md)), with their ports, "
      "methods and parameters. This page is generated from each component's declarations "
      "(`DeclareParam`, `AddInput`, `AddOutput`, `AddMethod`: "
      "[writing a component](writing-a-component.md)) by\n\n"
      "    saccade demo --list-components --markdown > docs/components.md\n\n"
      "and the test `docs.components` fails when it and the code differ.\n\n";
  for (const ComponentReference& c : components) {
    std::string anchor = c.type;  // GitHub's: "sim.head" -> "simhead"
    anchor.erase(std::remove(anchor.begin(), anchor.end(), '.'), anchor.end());
    out += fmt::format("- [{}](#{}): {}\n", c.type, anchor, c.description);
  }
  for (const ComponentReference& c : components) {
    out += fmt::format("\n## {}\n\n{}.\n\n", c.type, c.description);
    std::vector<std::string> ins, outs;
    for (const PortReference& p : c.inputs) {
      ins.push_back(
          fmt::format("`{}` (`{}`{})", p.name, p.message_type, p.required ? ", required" : ""));
    }
    for (const PortReference& p : c.outputs) {
      outs.push_back(fmt::format("`{}` (`{}`)", p.name, p.message_type));
    }
    out += "- inputs: " + (ins.empty() ? std::string("none") : Join(ins)) + "\n";
    out += "- outputs: " + (outs.empty() ? std::string("none") : Join(outs)) + "\n";
    for (const MethodReference& m : c.methods) {
      out += fmt::format("- method `{}` (`{}` → `{}`): {}\n", m.name, m.request_type, m.reply_type,
                         m.description);
    }
    if (c.params.empty()) {
      out += "\nNo parameters.\n";
      continue;
    }
    out += "\n| parameter | type | default | unit | meaning |\n|---|---|---|---|---|\n";
    for (const ParamInfo& p : c.params) {
      out += fmt::format("| `{}` | {} | {} | {} | {} |\n", p.name, Cell(p.TypeText()),
                         Cell(p.required ? "**required**" : "`" + p.DefaultText() + "`"),
                         Cell(p.unit), Cell(p.doc));
    }
  }
  return out;
}

nlohmann::json ComponentsJson(const std::vector<ComponentReference>& components) {
  nlohmann::json out = nlohmann::json::array();
  for (const ComponentReference& c : components) {
    nlohmann::json j{{"type", c.type}, {"description", c.description}};
    j["inputs"] = nlohmann::json::array();
    j["outputs"] = nlohmann::json::array();
    j["methods"] = nlohmann::json::array();
    j["params"] = nlohmann::json::array();
    for (const PortReference& p : c.inputs) {
      j["inputs"].push_back({{"name", p.name}, {"type", p.message_type}, {"required", p.required}});
    }
    for (const PortReference& p : c.outputs) {
      j["outputs"].push_back({{"name", p.name}, {"type", p.message_type}});
    }
    for (const MethodReference& m : c.methods) {
      j["methods"].push_back({{"name", m.name},
                              {"request", m.request_type},
                              {"reply", m.reply_type},
                              {"description", m.description}});
    }
    for (const ParamInfo& p : c.params) {
      nlohmann::json param{
          {"name", p.name},         {"type", p.TypeText()}, {"default", p.default_value},
          {"required", p.required}, {"unit", p.unit},       {"doc", p.doc}};
      if (!p.min.is_null()) param["min"] = p.min;
      if (!p.max.is_null()) param["max"] = p.max;
      if (p.min_open) param["min_exclusive"] = true;
      if (p.max_open) param["max_exclusive"] = true;
      if (!p.choices.empty()) param["choices"] = p.choices;
      if (p.path) param["path"] = true;
      j["params"].push_back(param);
    }
    out.push_back(j);
  }
  return out;
}

}  // namespace saccade::runtime
