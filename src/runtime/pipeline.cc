#include "saccade/runtime/pipeline.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include "core/internal_yaml.h"

namespace saccade::runtime {
namespace {

using saccade::internal::Entry;

// Names are used in "<component>.<port>" references: no dots, no spaces.
bool IsName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

int KeyLine(const YAML::Node& key, int fallback) {
  return key.Mark().is_null() ? fallback : key.Mark().line + 1;
}

// Plain YAML scalars become JSON numbers, booleans or null where they read as such; quoted
// ones stay strings.
nlohmann::json ToJson(const Entry& e) {
  const YAML::Node& node = e.node();
  if (!node.IsDefined() || node.IsNull()) return nullptr;
  if (node.IsSequence()) {
    nlohmann::json array = nlohmann::json::array();
    for (std::size_t i = 0; i < node.size(); ++i) {
      array.push_back(
          ToJson(Entry(node[i], fmt::format("{}[{}]", e.path(), i), &e.file(), e.line())));
    }
    return array;
  }
  if (node.IsMap()) {
    nlohmann::json object = nlohmann::json::object();
    for (auto it = node.begin(); it != node.end(); ++it) {
      const int key_line = KeyLine(it->first, e.line());
      if (!it->first.IsScalar()) {
        throw FileError(e.file(), key_line, e.path(), "expected a key name, got a list or a map");
      }
      const std::string key = it->first.Scalar();
      if (object.contains(key)) {
        throw FileError(e.file(), key_line, e.path() + "." + key, "duplicate key '" + key + "'");
      }
      object[key] = ToJson(Entry(it->second, e.path() + "." + key, &e.file(), key_line));
    }
    return object;
  }
  const std::string& text = node.Scalar();
  if (node.Tag() == "!") return text;  // quoted
  long long integer = 0;
  double number = 0.0;
  bool boolean = false;
  if (YAML::convert<long long>::decode(node, integer)) return integer;
  if (YAML::convert<double>::decode(node, number)) return number;
  if (YAML::convert<bool>::decode(node, boolean)) return boolean;
  return text;
}

ClockSpec ParseClock(const Entry& e) {
  e.ExpectMap({"mode", "step", "rate_hz", "steps", "source"},
              "a clock {mode, step | rate_hz, steps, source}");
  ClockSpec clock;
  const Entry mode = e.Get("mode");
  const std::string name = mode.AsString();
  if (name == "simulated") {
    clock.mode = ClockMode::kSimulated;
    if (const auto r = e.Find("rate_hz")) r->Fail("'rate_hz' is for mode realtime; use 'step'");
    if (const auto s = e.Find("step")) clock.step = s->AsPositive();
  } else if (name == "realtime") {
    clock.mode = ClockMode::kRealtime;
    if (const auto s = e.Find("step")) s->Fail("'step' is for mode simulated; use 'rate_hz'");
    if (const auto s = e.Find("source")) {
      s->Fail("'source' is for mode simulated: in real time the wall clock gives the time");
    }
    if (const auto r = e.Find("rate_hz")) clock.rate_hz = r->AsPositive();
    clock.step = 1.0 / clock.rate_hz;
  } else {
    mode.Fail("expected simulated or realtime, got " + mode.Describe());
  }
  if (const auto s = e.Find("steps")) {
    clock.steps = s->AsInteger(0, std::numeric_limits<int64_t>::max());
  }
  if (const auto s = e.Find("source")) {
    clock.source = s->AsString();
    clock.source_line = s->line();
    if (clock.source.find('.') == std::string::npos) {
      s->Fail("expected <component>.<input> (an input that reads a topic), got '" + clock.source +
              "'");
    }
  }
  return clock;
}

ConnectionSpec ParseConnection(const Entry& e, const std::string& input) {
  ConnectionSpec connection;
  connection.to_input = input;
  connection.line = e.line();
  std::optional<Entry> from;
  if (e.IsMap() && e.Has("topic")) {
    // A topic of another process: the transport reads the other keys (its options).
    connection.topic = e.Get("topic").AsNonEmptyString();
    connection.topic_options = ToJson(e);
    connection.topic_options.erase("topic");
    if (const auto it = connection.topic_options.find("delay");
        it != connection.topic_options.end()) {
      connection.delay = static_cast<int>(e.Get("delay").AsInteger(0, 1));
      connection.topic_options.erase(it);
    }
    return connection;
  }
  if (e.IsMap()) {
    e.ExpectMap({"from", "delay"},
                "a connection {from: component.output, delay: 0 | 1} or {topic: NAME, ...}");
    from = e.Get("from");
    if (const auto d = e.Find("delay")) connection.delay = static_cast<int>(d->AsInteger(0, 1));
  } else if (e.IsScalar()) {
    from = e;
  } else {
    e.Fail("expected a connection 'component.output' or {from: component.output, delay: 1}, got " +
           e.Describe());
  }
  const std::string text = from->AsString();
  const std::size_t dot = text.find('.');
  if (dot == std::string::npos || !IsName(text.substr(0, dot)) || !IsName(text.substr(dot + 1))) {
    from->Fail("expected 'component.output', got '" + text + "'");
  }
  connection.from_component = text.substr(0, dot);
  connection.from_output = text.substr(dot + 1);
  return connection;
}

// The type and params of a component entry (pipeline or hardware file).
void ParseTypeAndParams(const Entry& e, ComponentSpec* spec) {
  const Entry type = e.Get("type");
  spec->type = type.AsNonEmptyString();
  spec->type_line = type.line();
  spec->params_line = e.line();
  if (const auto params = e.Find("params")) {
    spec->params_line = params->line();
    if (!params->IsNull()) {
      if (!params->IsMap()) params->Fail("expected a map of parameters, got " + params->Describe());
      spec->params = ToJson(*params);
    }
  }
}

// `scene: FILE` at the top of a pipeline or hardware file, resolved against its folder.
std::optional<ResourceSpec> ParseScene(const Entry& root, const std::string& file) {
  const auto scene = root.Find("scene");
  if (!scene) return std::nullopt;
  const std::filesystem::path relative = scene->AsNonEmptyString();
  return ResourceSpec{relative.is_absolute()
                          ? relative.string()
                          : (std::filesystem::path(file).parent_path() / relative).string(),
                      file, scene->line()};
}

// A hardware file: component name -> its type and params; `scene` its scene, if it names one.
std::map<std::string, ComponentSpec> LoadHardware(const std::string& path,
                                                  std::optional<ResourceSpec>* scene) {
  // A regular file of bounded size (not /dev/zero, a folder or a pipe).
  const std::string text = saccade::internal::ReadConfigFile(path, "hardware file");
  const YAML::Node root_node = saccade::internal::ParseYaml(text, path);
  const Entry root(root_node, "", &path, 1);
  root.ExpectMap({"scene", "components"},
                 "a hardware file {scene, components: {name: {type, params}}}");
  *scene = ParseScene(root, path);
  const Entry components = root.Get("components");
  if (!components.IsMap() || components.node().size() == 0) {
    components.Fail("expected a map of components {name: {type, params}}, got " +
                    components.Describe());
  }
  std::map<std::string, ComponentSpec> hardware;
  for (auto it = components.node().begin(); it != components.node().end(); ++it) {
    const int key_line = KeyLine(it->first, components.line());
    const std::string name = it->first.IsScalar() ? it->first.Scalar() : "";
    const std::string key = "components." + name;
    if (!IsName(name)) {
      throw FileError(
          path, key_line, "components",
          "expected a component name of letters, digits, '_' or '-', got '" + name + "'");
    }
    const Entry entry(it->second, key, &path, key_line);
    entry.ExpectMap({"type", "params"}, "a hardware component {type, params}");
    ComponentSpec spec;
    spec.name = name;
    spec.line = key_line;
    spec.params_file = path;
    ParseTypeAndParams(entry, &spec);
    if (!hardware.emplace(name, std::move(spec)).second) {
      throw FileError(path, key_line, key, "duplicate component '" + name + "'");
    }
  }
  return hardware;
}

ComponentSpec ParseComponent(const Entry& e) {
  e.ExpectMap({"name", "type", "params", "inputs", "outputs"},
              "a component {name, type, params, inputs, outputs}");
  ComponentSpec spec;
  spec.line = e.line();
  const Entry name = e.Get("name");
  spec.name = name.AsNonEmptyString();
  if (!IsName(spec.name)) {
    name.Fail("expected a name of letters, digits, '_' or '-' (no dots), got '" + spec.name + "'");
  }
  if (e.Has("type")) {
    ParseTypeAndParams(e, &spec);
  } else if (e.Has("params")) {
    e.Get("params").Fail("component '" + spec.name +
                         "' has params but no type (a hardware component takes both from the "
                         "hardware file)");
  }
  if (const auto inputs = e.Find("inputs")) {
    if (!inputs->IsNull()) {
      if (!inputs->IsMap()) {
        inputs->Fail("expected a map input: component.output, got " + inputs->Describe());
      }
      std::set<std::string> seen;
      for (auto it = inputs->node().begin(); it != inputs->node().end(); ++it) {
        const int key_line = KeyLine(it->first, inputs->line());
        if (!it->first.IsScalar()) {
          throw FileError(inputs->file(), key_line, inputs->path(), "expected an input name");
        }
        const std::string input = it->first.Scalar();
        const std::string path = inputs->path() + "." + input;
        if (!seen.insert(input).second) {
          throw FileError(inputs->file(), key_line, path,
                          "input '" + input + "' is connected twice");
        }
        spec.inputs.push_back(
            ParseConnection(Entry(it->second, path, &inputs->file(), key_line), input));
      }
    }
  }
  if (const auto outputs = e.Find("outputs")) {
    if (!outputs->IsNull()) {
      if (!outputs->IsMap()) {
        outputs->Fail("expected a map output: topic (or {topic: NAME, ...}), got " +
                      outputs->Describe());
      }
      for (auto it = outputs->node().begin(); it != outputs->node().end(); ++it) {
        const int key_line = KeyLine(it->first, outputs->line());
        if (!it->first.IsScalar()) {
          throw FileError(outputs->file(), key_line, outputs->path(), "expected an output name");
        }
        TopicOutputSpec out;
        out.output = it->first.Scalar();
        out.line = key_line;
        const Entry value(it->second, outputs->path() + "." + out.output, &outputs->file(),
                          key_line);
        if (value.IsMap()) {
          out.topic = value.Get("topic").AsNonEmptyString();
          out.topic_options = ToJson(value);
          out.topic_options.erase("topic");
        } else {
          out.topic = value.AsNonEmptyString();
        }
        for (const TopicOutputSpec& other : spec.topic_outputs) {
          if (other.output == out.output && other.topic == out.topic) {
            throw FileError(outputs->file(), key_line, value.path(),
                            "output '" + out.output + "' is written to '" + out.topic + "' twice");
          }
        }
        spec.topic_outputs.push_back(std::move(out));
      }
    }
  }
  return spec;
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text.empty() ? "(none)" : text;
}

template <typename Ports>
std::string PortNames(const Ports& ports) {
  std::vector<std::string> names;
  for (const auto& port : ports) names.push_back(port->name() + " (" + port->message_type() + ")");
  return JoinNames(names);
}

std::string ComponentKey(std::size_t index) { return fmt::format("components[{}]", index); }

// The top-level settings: transport, scene, clock, seed, threads, on_error.
void ParseSettings(const Entry& root, PipelineSpec* spec) {
  if (const auto transport = root.Find("transport")) {
    if (!transport->IsMap()) transport->Fail("expected a map, got " + transport->Describe());
    spec->transport = ToJson(*transport);
    spec->transport_line = transport->line();
  }
  if (auto scene = ParseScene(root, spec->file)) spec->resources["scene"] = std::move(*scene);
  if (const auto clock = root.Find("clock")) spec->clock = ParseClock(*clock);
  if (const auto seed = root.Find("seed")) spec->seed = seed->AsUint64();
  if (const auto threads = root.Find("threads")) {
    spec->threads = static_cast<int>(threads->AsInteger(0, kMaxThreads));
  }
  if (const auto on_error = root.Find("on_error")) {
    const std::string value = on_error->AsString();
    if (value == "stop") {
      spec->on_error = OnError::kStop;
    } else if (value == "continue") {
      spec->on_error = OnError::kContinue;
    } else {
      on_error->Fail("expected stop or continue, got " + on_error->Describe());
    }
  }
}

// The `components:` list, in order; names unique.
std::vector<ComponentSpec> ParseComponents(const Entry& root) {
  const Entry components = root.Get("components");
  const std::vector<Entry> entries = components.AsSequence("components");
  if (entries.empty()) components.Fail("expected at least one component, got an empty list");
  if (entries.size() > static_cast<std::size_t>(kMaxComponents)) {
    components.Fail(fmt::format("{} components, more than the {} a pipeline may have",
                                entries.size(), kMaxComponents));
  }
  std::vector<ComponentSpec> specs;
  std::map<std::string, int> lines;  // name -> line of its first use
  for (const Entry& entry : entries) {
    ComponentSpec component = ParseComponent(entry);
    const auto [it, inserted] = lines.emplace(component.name, component.line);
    if (!inserted) {
      entry.Get("name").Fail(fmt::format("duplicate component name '{}' (first at line {})",
                                         component.name, it->second));
    }
    specs.push_back(std::move(component));
  }
  return specs;
}

// Reads the hardware file (`hardware`, else the file's `hardware:` line) and fills in the
// components without a type from it; each of its components must be in the pipeline.
void ApplyHardwareFile(const Entry& root, const std::string& hardware, PipelineSpec* spec) {
  const std::string& source = spec->file;
  std::optional<Entry> hardware_entry = root.Find("hardware");
  if (!hardware.empty()) {
    spec->hardware_file = hardware;
  } else if (hardware_entry) {
    const std::filesystem::path relative = hardware_entry->AsNonEmptyString();
    spec->hardware_file = relative.is_absolute()
                              ? relative.string()
                              : (std::filesystem::path(source).parent_path() / relative).string();
  }
  std::map<std::string, ComponentSpec> parts;
  if (!spec->hardware_file.empty()) {
    try {
      std::optional<ResourceSpec> scene;
      parts = LoadHardware(spec->hardware_file, &scene);
      // The hardware file's scene is a default: the pipeline's own `scene:` line wins over its
      // `hardware:` line's file, and a hardware file given instead of that line (`--hardware`)
      // wins over both, as the more specific choice in each case.
      if (scene && (!hardware.empty() || spec->resources.count("scene") == 0)) {
        spec->resources["scene"] = std::move(*scene);
      }
    } catch (const FileError& error) {
      if (hardware.empty() && hardware_entry && error.line() == 0) {
        hardware_entry->Fail(error.what());  // a missing file: name the pipeline's line too
      }
      throw;
    }
  }
  for (std::size_t i = 0; i < spec->components.size(); ++i) {
    ComponentSpec& component = spec->components[i];
    const auto part = parts.find(component.name);
    if (!component.type.empty()) {
      if (part != parts.end()) {
        throw FileError(source, component.type_line, ComponentKey(i) + ".type",
                        fmt::format("component '{}' is in the hardware file {} (line {}): leave "
                                    "its type and params to that file",
                                    component.name, spec->hardware_file, part->second.line));
      }
      continue;
    }
    if (part == parts.end()) {
      throw FileError(source, component.line, ComponentKey(i),
                      spec->hardware_file.empty()
                          ? fmt::format("component '{}' has no type (and the pipeline names no "
                                        "hardware file that would give it one)",
                                        component.name)
                          : fmt::format("component '{}' has no type, and the hardware file {} "
                                        "does not define it",
                                        component.name, spec->hardware_file));
    }
    component.type = part->second.type;
    component.params = part->second.params;
    component.type_line = part->second.type_line;
    component.params_line = part->second.params_line;
    component.params_file = part->second.params_file;
    parts.erase(part);
  }
  if (!parts.empty()) {
    const ComponentSpec& extra = parts.begin()->second;
    throw FileError(extra.params_file, extra.line, "components." + extra.name,
                    fmt::format("the hardware file defines '{}' but the pipeline {} has no "
                                "component of that name",
                                extra.name, source));
  }
}

}  // namespace

PipelineSpec ParsePipeline(const std::string& text, const std::string& source,
                           const std::string& hardware) {
  const YAML::Node root_node = saccade::internal::ParseYaml(text, source);
  const Entry root(root_node, "", &source, 1);
  root.ExpectMap(
      {"clock", "seed", "threads", "on_error", "scene", "hardware", "transport", "components"},
      "a pipeline {clock, seed, threads, on_error, scene, hardware, transport, components}");
  PipelineSpec spec;
  spec.file = source;
  ParseSettings(root, &spec);
  spec.components = ParseComponents(root);
  // The hardware file fills in the components without a type.
  ApplyHardwareFile(root, hardware, &spec);
  return spec;
}

PipelineSpec LoadPipelineFile(const std::string& path, const std::string& hardware) {
  return ParsePipeline(saccade::internal::ReadConfigFile(path, "pipeline file"), path, hardware);
}

void ReplaceScene(PipelineSpec& spec, const std::string& path, const std::string& origin) {
  namespace fs = std::filesystem;
  const std::string scene = fs::absolute(path).lexically_normal().string();
  if (!fs::exists(scene)) throw InvalidArgument(origin + " " + path + ": no such file");
  spec.resources["scene"] = ResourceSpec{scene, origin, 0};
  for (ComponentSpec& c : spec.components) {
    if (c.params.is_object() && c.params.contains("scene")) c.params["scene"] = scene;
  }
}

uint64_t ComponentSeed(uint64_t pipeline_seed, const std::string& component_name) {
  // FNV-1a of the name, then SplitMix64's finaliser over the mix: fixed on every platform,
  // unlike std::hash.
  uint64_t hash = 14695981039346656037ull;
  for (const unsigned char c : component_name) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  uint64_t z = pipeline_seed + 0x9e3779b97f4a7c15ull * (hash | 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

Pipeline::Pipeline(Pipeline&&) noexcept = default;
Pipeline& Pipeline::operator=(Pipeline&&) noexcept = default;
Pipeline::~Pipeline() = default;

Pipeline Pipeline::LoadFile(const std::string& path, const ComponentRegistry& registry) {
  return Build(LoadPipelineFile(path), registry);
}

Pipeline Pipeline::LoadString(const std::string& text, const std::string& source,
                              const ComponentRegistry& registry) {
  return Build(ParsePipeline(text, source), registry);
}

namespace {

// Build's phases, in order: names, resources, components, topics, clock source, connections.

// Throws FileError naming the second of two components of the same name.
void CheckUniqueNames(const PipelineSpec& spec) {
  std::set<std::string> names;
  for (std::size_t i = 0; i < spec.components.size(); ++i) {
    const ComponentSpec& c = spec.components[i];
    if (!names.insert(c.name).second) {
      throw FileError(spec.file, c.line, ComponentKey(i) + ".name",
                      "duplicate component name '" + c.name + "'");
    }
  }
}

// Each component's index by name (the first, should two share one).
std::map<std::string, std::size_t> NameIndex(const PipelineSpec& spec) {
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < spec.components.size(); ++i)
    index.emplace(spec.components[i].name, i);
  return index;
}

// The shared resources, loaded before any component so that a bad file is reported at the
// line that names it.
std::shared_ptr<Resources> LoadResources(const PipelineSpec& spec,
                                         const ComponentRegistry& registry) {
  auto resources = std::make_shared<Resources>(registry.resource_loaders());
  for (const auto& [kind, resource] : spec.resources) {
    try {
      resources->SetDefault(kind, resource.path);
      resources->LoadDefault(kind);
    } catch (const Error& error) {
      throw FileError(resource.file, resource.line, kind, error.what());
    }
  }
  return resources;
}

// The file's components, created and configured in order.
std::vector<std::unique_ptr<Component>> CreateComponents(
    const PipelineSpec& spec, const ComponentRegistry& registry,
    const std::shared_ptr<Resources>& resources) {
  const std::string& file = spec.file;
  // Relative paths in params resolve against the pipeline file's folder.
  const std::string base_dir = std::filesystem::path(file).parent_path().string();
  std::vector<std::unique_ptr<Component>> components;
  for (std::size_t i = 0; i < spec.components.size(); ++i) {
    const ComponentSpec& c = spec.components[i];
    // A hardware component's type and params come from its hardware file.
    const std::string& params_file = c.params_file.empty() ? file : c.params_file;
    const std::string type_key =
        c.params_file.empty() ? ComponentKey(i) + ".type" : "components." + c.name + ".type";
    const std::string params_key =
        c.params_file.empty() ? ComponentKey(i) + ".params" : "components." + c.name + ".params";
    if (!registry.Has(c.type)) {
      throw FileError(params_file, c.type_line, type_key,
                      "unknown component type '" + c.type + "' for component '" + c.name +
                          "'; known types: " + JoinNames(registry.Types()));
    }
    std::unique_ptr<Component> component = registry.Create(c.type);
    component->Initialise(c.name, ComponentSeed(spec.seed, c.name),
                          c.params_file.empty()
                              ? base_dir
                              : std::filesystem::path(c.params_file).parent_path().string(),
                          resources);
    try {
      component->Configure(c.params);
    } catch (const std::exception& error) {
      throw FileError(params_file, c.params_line, params_key,
                      "component '" + c.name + "' (" + c.type + "): " + error.what());
    }
    components.push_back(std::move(component));
  }
  return components;
}

bool HasTopics(const PipelineSpec& spec) {
  return std::any_of(spec.components.begin(), spec.components.end(), [](const ComponentSpec& c) {
    return !c.topic_outputs.empty() ||
           std::any_of(c.inputs.begin(), c.inputs.end(),
                       [](const ConnectionSpec& x) { return !x.topic.empty(); });
  });
}

// The components as built: the file's, with a topic's reader just before each consumer of a
// topic (the file comment).
struct BuiltComponents {
  PipelineSpec spec;  // the file's, with the readers and the connections to them
  std::vector<std::unique_ptr<Component>> components;
  std::vector<std::size_t> file_index;  // the file's index of each (a reader: its consumer's)
  std::vector<std::pair<TopicOutputSpec, std::size_t>> topic_writers;  // and their component
};

// The reader of the topic that `connection` (of the file's component `i`, `c`) names; turns
// the connection into one from the reader, whose spec goes to `built`.
std::unique_ptr<Component> MakeTopicReader(const PipelineSpec& spec, std::size_t i,
                                           const ComponentSpec& c, ConnectionSpec& connection,
                                           const Component& consumer,
                                           const TopicTransport* transport,
                                           const std::shared_ptr<Resources>& resources,
                                           BuiltComponents& built) {
  const std::string& file = spec.file;
  const std::string key = ComponentKey(i) + ".inputs." + connection.to_input;
  if (transport == nullptr) {
    throw FileError(file, connection.line, key,
                    "input '" + connection.to_input + "' reads the topic '" + connection.topic +
                        "', but this program has no topic transport (DDS)");
  }
  const InputBase* input = consumer.FindInput(connection.to_input);
  if (input == nullptr) {
    throw FileError(file, connection.line, key,
                    fmt::format("component '{}' ({}) has no input '{}'; its inputs: {}", c.name,
                                c.type, connection.to_input, PortNames(consumer.inputs())));
  }
  ComponentSpec reader;
  reader.name = c.name + "-" + connection.to_input + "-topic";
  reader.type = transport->name + " reader of " + connection.topic;
  reader.reads_for = c.name;
  reader.line = reader.type_line = reader.params_line = connection.line;
  TopicEndpoint endpoint{connection.topic, input->message_type(), connection.topic_options, &spec,
                         c.name + "." + connection.to_input};
  std::unique_ptr<Component> component;
  try {
    component = transport->make_reader(endpoint);
  } catch (const std::exception& error) {
    throw FileError(file, connection.line, key, error.what());
  }
  component->Initialise(reader.name, ComponentSeed(spec.seed, reader.name),
                        std::filesystem::path(file).parent_path().string(), resources);
  connection.from_component = reader.name;
  connection.from_output = "message";
  built.spec.components.push_back(std::move(reader));
  built.file_index.push_back(i);
  return component;
}

// The file's components with the readers of its topic inputs, and the outputs that write a
// topic; as they are when the file names no topic.
BuiltComponents AddTopicReaders(const PipelineSpec& spec,
                                std::vector<std::unique_ptr<Component>> components,
                                const TopicTransport* transport,
                                const std::shared_ptr<Resources>& resources) {
  BuiltComponents built;
  const std::size_t n = spec.components.size();
  if (!HasTopics(spec)) {
    built.spec = spec;
    built.components = std::move(components);
    for (std::size_t i = 0; i < n; ++i) built.file_index.push_back(i);
    return built;
  }
  built.spec = spec;
  built.spec.components.clear();
  for (std::size_t i = 0; i < n; ++i) {
    ComponentSpec c = spec.components[i];
    for (ConnectionSpec& connection : c.inputs) {
      if (connection.topic.empty()) continue;
      built.components.push_back(
          MakeTopicReader(spec, i, c, connection, *components[i], transport, resources, built));
    }
    for (const TopicOutputSpec& out : c.topic_outputs) {
      if (transport == nullptr) {
        throw FileError(spec.file, out.line, ComponentKey(i) + ".outputs." + out.output,
                        "output '" + out.output + "' writes the topic '" + out.topic +
                            "', but this program has no topic transport (DDS)");
      }
      built.topic_writers.emplace_back(out, built.spec.components.size());
    }
    built.spec.components.push_back(std::move(c));
    built.components.push_back(std::move(components[i]));
    built.file_index.push_back(i);
  }
  return built;
}

// The clock's source (`clock.source`): the reader of a topic input, whose stamps time the
// steps; nullptr when the file names none.
TimeSource* FindTimeSource(const BuiltComponents& b,
                           const std::map<std::string, std::size_t>& index,
                           const TopicTransport* transport) {
  const PipelineSpec& built = b.spec;
  if (built.clock.source.empty()) return nullptr;
  const std::string& source = built.clock.source;
  const auto Fail = [&](const std::string& what) {
    throw FileError(built.file, built.clock.source_line, "clock.source", what);
  };
  if (built.clock.mode != ClockMode::kSimulated) {
    Fail("'source' is for mode simulated: in real time the wall clock gives the time");
  }
  const std::string name = source.substr(0, source.find('.'));
  const std::string input = source.substr(source.find('.') + 1);
  const auto consumer = index.find(name);
  if (consumer == index.end() || !built.components[consumer->second].reads_for.empty()) {
    std::vector<std::string> names;
    for (const ComponentSpec& c : built.components) {
      if (c.reads_for.empty()) names.push_back(c.name);
    }
    Fail(fmt::format("unknown component '{}' in '{}'; components: {}", name, source,
                     JoinNames(names)));
  }
  const std::vector<ConnectionSpec>& inputs = built.components[consumer->second].inputs;
  const auto connection = std::find_if(inputs.begin(), inputs.end(),
                                       [&](const auto& c) { return c.to_input == input; });
  if (connection == inputs.end()) {
    Fail(fmt::format("component '{}' has no input '{}' connected in the file", name, input));
  }
  const auto reader = index.find(connection->from_component);
  if (reader == index.end() || built.components[reader->second].reads_for != name) {
    Fail(
        fmt::format("input '{}' reads '{}.{}', not a topic: only a topic's stamps can time "
                    "the steps",
                    source, connection->from_component, connection->from_output));
  }
  auto* time_source = dynamic_cast<TimeSource*>(b.components[reader->second].get());
  if (time_source == nullptr) {
    Fail(fmt::format("the {} transport's reader of '{}' gives no time", transport->name, source));
  }
  return time_source;
}

// The message for an immediate connection from component j to component i (j >= i): the
// cycle it closes, naming its components, or the order to change. `readers`: the immediate
// edges producer -> consumers.
std::string CycleMessage(const PipelineSpec& built, std::size_t i, std::size_t j,
                         const std::vector<std::vector<std::size_t>>& readers,
                         const std::string& from) {
  const std::size_t m = built.components.size();
  const std::string& consumer = built.components[i].name;
  // The producer runs after (or is) the consumer: find the consumer's path to it.
  std::vector<std::size_t> parent(m, m);
  std::vector<std::size_t> queue{i};
  std::vector<bool> seen(m, false);
  seen[i] = true;
  for (std::size_t q = 0; q < queue.size() && !seen[j]; ++q) {
    for (std::size_t next : readers[queue[q]]) {
      if (!seen[next]) {
        seen[next] = true;
        parent[next] = queue[q];
        queue.push_back(next);
      }
    }
  }
  if (j == i || seen[j]) {
    std::string cycle = consumer;
    if (j != i) {
      std::vector<std::string> path;
      for (std::size_t k = j; k != m; k = parent[k]) path.push_back(built.components[k].name);
      std::reverse(path.begin(), path.end());
      cycle.clear();
      for (const std::string& name : path) cycle += name + " -> ";
    } else {
      cycle += " -> ";
    }
    cycle += consumer;
    return fmt::format(
        "cycle: {} without a delay; add 'delay: 1' to one of its connections, e.g. this one: "
        "{{from: {}, delay: 1}}",
        cycle, from);
  }
  const std::string& producer = built.components[j].name;
  return fmt::format(
      "'{}' runs after '{}' in execution order, so this connection closes a cycle: list '{}' "
      "before '{}', or add 'delay: 1' to read the previous step's message ({{from: {}, delay: "
      "1}})",
      producer, consumer, producer, consumer, from);
}

// Connects every input of the built components to its producer's output, checking names,
// types and order; then checks that the required inputs are connected.
void ConnectInputs(const BuiltComponents& b, const std::map<std::string, std::size_t>& index,
                   double* delivery_seconds) {
  const PipelineSpec& built = b.spec;
  const std::string& file = built.file;
  const std::size_t m = built.components.size();
  // Immediate edges producer -> consumer, to name the components of a cycle.
  std::vector<std::vector<std::size_t>> readers(m);
  for (std::size_t i = 0; i < m; ++i) {
    for (const ConnectionSpec& connection : built.components[i].inputs) {
      const auto it = index.find(connection.from_component);
      if (it != index.end() && connection.delay == 0) readers[it->second].push_back(i);
    }
  }
  for (std::size_t i = 0; i < m; ++i) {
    const ComponentSpec& c = built.components[i];
    Component& consumer = *b.components[i];
    for (const ConnectionSpec& connection : c.inputs) {
      const std::string key = ComponentKey(b.file_index[i]) + ".inputs." + connection.to_input;
      const std::string from = connection.from_component + "." + connection.from_output;
      const auto Fail = [&](const std::string& what) {
        throw FileError(file, connection.line, key, what);
      };
      InputBase* input = consumer.FindInput(connection.to_input);
      if (input == nullptr) {
        Fail(fmt::format("component '{}' ({}) has no input '{}'; its inputs: {}", c.name, c.type,
                         connection.to_input, PortNames(consumer.inputs())));
      }
      const auto it = index.find(connection.from_component);
      if (it == index.end()) {
        std::vector<std::string> names;
        for (const ComponentSpec& other : built.components) names.push_back(other.name);
        Fail(fmt::format("unknown component '{}' in '{}'; components: {}",
                         connection.from_component, from, JoinNames(names)));
      }
      const std::size_t j = it->second;
      const Component& producer = *b.components[j];
      OutputBase* output = producer.FindOutput(connection.from_output);
      if (output == nullptr) {
        Fail(fmt::format("component '{}' ({}) has no output '{}'; its outputs: {}", producer.name(),
                         built.components[j].type, connection.from_output,
                         PortNames(producer.outputs())));
      }
      if (output->message_type() != input->message_type()) {
        Fail(fmt::format("type mismatch: output '{}' sends {}, input '{}.{}' expects {}", from,
                         output->message_type(), c.name, connection.to_input,
                         input->message_type()));
      }
      if (j >= i && connection.delay == 0) Fail(CycleMessage(built, i, j, readers, from));
      try {
        input->ConnectFrom(*output, connection.delay,
                           [delivery_seconds](double seconds) { *delivery_seconds += seconds; });
      } catch (const Error& error) {
        Fail(error.what());
      }
    }
    for (const auto& input : consumer.inputs()) {
      if (input->required() && !input->connected()) {
        throw FileError(file, c.line, ComponentKey(b.file_index[i]) + ".inputs",
                        fmt::format("required input '{}' ({}) of component '{}' ({}) is not "
                                    "connected",
                                    input->name(), input->message_type(), c.name, c.type));
      }
    }
  }
}

// Attaches the topic writers of the outputs that name a topic; returns their end-of-step work.
std::vector<std::function<void(const StepContext&)>> AttachTopicWriters(
    const PipelineSpec& spec, const BuiltComponents& b, const TopicTransport* transport) {
  std::vector<std::function<void(const StepContext&)>> step_ends;
  for (const auto& [out, i] : b.topic_writers) {
    const ComponentSpec& c = b.spec.components[i];
    const std::string key = "components." + c.name + ".outputs." + out.output;
    OutputBase* output = b.components[i]->FindOutput(out.output);
    if (output == nullptr) {
      throw FileError(spec.file, out.line, key,
                      fmt::format("component '{}' ({}) has no output '{}'; its outputs: {}", c.name,
                                  c.type, out.output, PortNames(b.components[i]->outputs())));
    }
    try {
      auto step_end = transport->attach_writer(
          TopicEndpoint{out.topic, output->message_type(), out.topic_options, &spec,
                        c.name + "." + out.output},
          *output);
      if (step_end) step_ends.push_back(std::move(step_end));
    } catch (const std::exception& error) {
      throw FileError(spec.file, out.line, key, error.what());
    }
  }
  return step_ends;
}

}  // namespace

Pipeline Pipeline::Build(const PipelineSpec& spec, const ComponentRegistry& registry) {
  CheckUniqueNames(spec);
  Pipeline pipeline;
  pipeline.resources_ = LoadResources(spec, registry);
  const TopicTransport* transport = registry.topic_transport();
  BuiltComponents built = AddTopicReaders(
      spec, CreateComponents(spec, registry, pipeline.resources_), transport, pipeline.resources_);
  const std::map<std::string, std::size_t> index = NameIndex(built.spec);
  pipeline.time_source_ = FindTimeSource(built, index, transport);
  ConnectInputs(built, index, pipeline.delivery_seconds_.get());
  pipeline.step_ends_ = AttachTopicWriters(spec, built, transport);
  if (HasTopics(spec) && transport->attach_pipeline) {
    try {
      auto step_begin = transport->attach_pipeline(spec);
      if (step_begin) pipeline.step_begins_.push_back(std::move(step_begin));
    } catch (const std::exception& error) {
      throw FileError(spec.file, spec.transport_line, "transport", error.what());
    }
  }
  pipeline.spec_ = std::move(built.spec);
  pipeline.components_ = std::move(built.components);
  return pipeline;
}

Component* Pipeline::Find(const std::string& name) const {
  for (const auto& component : components_) {
    if (component->name() == name) return component.get();
  }
  return nullptr;
}

void Pipeline::BeginStep(const StepContext& context) {
  for (const auto& step_begin : step_begins_) step_begin(context);
}

void Pipeline::EndStep(const StepContext& context) {
  for (const auto& step_end : step_ends_) step_end(context);
}

void Pipeline::DeliverDelayed() {
  for (const auto& component : components_) {
    for (const auto& input : component->inputs()) input->DeliverDelayed();
  }
}

double Pipeline::TakeDeliverySeconds() {
  const double seconds = *delivery_seconds_;
  *delivery_seconds_ = 0.0;
  return seconds;
}

nlohmann::json Pipeline::Call(const std::string& component, const std::string& method,
                              const nlohmann::json& request) const {
  const Component* c = Find(component);
  if (c == nullptr) {
    throw MethodError(component + "." + method, "no component named '" + component + "'");
  }
  const MethodBase* m = c->FindMethod(method);
  if (m == nullptr) {
    std::vector<std::string> names;
    for (const auto& known : c->methods()) names.push_back(known->name());
    throw MethodError(component + "." + method,
                      "component '" + component + "' has no such method (it has: " +
                          (names.empty() ? std::string("none") : JoinNames(names)) + ")");
  }
  return m->CallJson(request);
}

}  // namespace saccade::runtime
