#pragma once
// The reference of the component types a pipeline can name: each type's description, ports,
// methods and declared parameters (params.h), read from a new instance of it. `saccade demo
// --list-components` prints it as text, as JSON, or as the Markdown of docs/components.md.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "saccade/runtime/component_registry.h"
#include "saccade/runtime/params.h"

namespace saccade::runtime {

struct PortReference {
  std::string name;
  std::string message_type;  ///< "runtime.image"
  bool required = false;     ///< inputs only
};

struct MethodReference {
  std::string name, request_type, reply_type, description;
};

/// One component type. Ports declared in Configure (sim.cameras' one per camera) are not
/// known before it is configured; the type's parameter docs say so.
struct ComponentReference {
  std::string type;
  std::string description;
  std::vector<PortReference> inputs, outputs;
  std::vector<MethodReference> methods;
  std::vector<ParamInfo> params;
};

/// Every registered type, sorted by type. Constructs (never configures) one of each.
std::vector<ComponentReference> DescribeComponents(const ComponentRegistry& registry);

/// For people: a block per type, a line per port, method and parameter.
std::string ComponentsText(const std::vector<ComponentReference>& components);
/// docs/components.md.
std::string ComponentsMarkdown(const std::vector<ComponentReference>& components);
/// For programs: [{type, description, inputs, outputs, methods, params: [{name, type, default,
/// required, min, max, choices, unit, doc}]}].
nlohmann::json ComponentsJson(const std::vector<ComponentReference>& components);

}  // namespace saccade::runtime
