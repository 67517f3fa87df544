#include "saccade/runtime/message.h"

#include <fmt/format.h>

#include <utility>

namespace saccade::runtime {
namespace {

std::string Expect(const nlohmann::json& value, const char* type, const char* key,
                   const char* what) {
  return fmt::format("{}: field '{}': expected {}, got {}", type, key, what, value.dump());
}

MessageRegistry MakeGlobal() {
  MessageRegistry registry;
  registry.Register<Tick>();
  registry.Register<Value>();
  registry.Register<Text>();
  registry.Register<Empty>();
  registry.Register<ImageMessage>();
  return registry;
}

}  // namespace

const nlohmann::json& JsonField(const nlohmann::json& json, const char* type, const char* key) {
  if (!json.is_object()) {
    throw Error(fmt::format("{}: expected a JSON object, got {}", type, json.dump()));
  }
  const auto it = json.find(key);
  if (it == json.end()) throw Error(fmt::format("{}: missing field '{}'", type, key));
  return *it;
}

double JsonNumber(const nlohmann::json& json, const char* type, const char* key) {
  const nlohmann::json& value = JsonField(json, type, key);
  if (!value.is_number()) throw Error(Expect(value, type, key, "a number"));
  return value.get<double>();
}

int64_t JsonInteger(const nlohmann::json& json, const char* type, const char* key) {
  const nlohmann::json& value = JsonField(json, type, key);
  if (!value.is_number_integer()) throw Error(Expect(value, type, key, "an integer"));
  return value.get<int64_t>();
}

bool JsonBool(const nlohmann::json& json, const char* type, const char* key) {
  const nlohmann::json& value = JsonField(json, type, key);
  if (!value.is_boolean()) throw Error(Expect(value, type, key, "true or false"));
  return value.get<bool>();
}

std::string JsonString(const nlohmann::json& json, const char* type, const char* key) {
  const nlohmann::json& value = JsonField(json, type, key);
  if (!value.is_string()) throw Error(Expect(value, type, key, "a string"));
  return value.get<std::string>();
}

std::vector<double> JsonNumbers(const nlohmann::json& json, const char* type, const char* key,
                                std::size_t n) {
  const nlohmann::json& value = JsonField(json, type, key);
  const std::string what = fmt::format("an array of {} numbers", n);
  if (!value.is_array() || value.size() != n) throw Error(Expect(value, type, key, what.c_str()));
  std::vector<double> out;
  for (const nlohmann::json& item : value) {
    if (!item.is_number()) throw Error(Expect(value, type, key, what.c_str()));
    out.push_back(item.get<double>());
  }
  return out;
}

MessageRegistry& MessageRegistry::Global() {
  static MessageRegistry registry = MakeGlobal();
  return registry;
}

const MessageType* MessageRegistry::Find(const std::string& name) const {
  const auto it = types_.find(name);
  return it == types_.end() ? nullptr : &it->second;
}

std::vector<std::string> MessageRegistry::Names() const {
  std::vector<std::string> names;
  for (const auto& [name, type] : types_) names.push_back(name);
  return names;
}

void MessageRegistry::Add(MessageType type) {
  std::string name = type.name;
  types_.emplace(std::move(name), std::move(type));
}

nlohmann::json MessageTraits<Tick>::ToJson(const Tick& m) {
  return {{"step", m.step}, {"time", m.time}};
}

Tick MessageTraits<Tick>::FromJson(const nlohmann::json& j) {
  return {JsonInteger(j, kName, "step"), JsonNumber(j, kName, "time")};
}

nlohmann::json MessageTraits<Value>::ToJson(const Value& m) { return {{"value", m.value}}; }

Value MessageTraits<Value>::FromJson(const nlohmann::json& j) {
  return {JsonNumber(j, kName, "value")};
}

nlohmann::json MessageTraits<Empty>::ToJson(const Empty&) { return nlohmann::json::object(); }

Empty MessageTraits<Empty>::FromJson(const nlohmann::json& j) {
  if (!j.is_null() && !(j.is_object() && j.empty())) {
    throw Error(fmt::format("{}: expected {{}}, got {}", kName, j.dump()));
  }
  return {};
}

nlohmann::json MessageTraits<Text>::ToJson(const Text& m) { return {{"text", m.text}}; }

Text MessageTraits<Text>::FromJson(const nlohmann::json& j) {
  return {JsonString(j, kName, "text")};
}

nlohmann::json MessageTraits<ImageMessage>::ToJson(const ImageMessage& m) {
  if (!m.image) return nullptr;
  const Image& image = *m.image;
  const ImageMetadata& meta = image.metadata();
  // Metadata only: pixels never go into text (DESIGN.md).
  return {{"camera", meta.camera},    {"frame_index", meta.frame_index},
          {"time", meta.time},        {"width", image.width()},
          {"height", image.height()}, {"format", ToString(image.format())}};
}

ImageMessage MessageTraits<ImageMessage>::FromJson(const nlohmann::json& j) {
  if (j.is_null()) return {};
  const int64_t width = JsonInteger(j, kName, "width");
  const int64_t height = JsonInteger(j, kName, "height");
  for (const auto& [key, side] : {std::pair{"width", width}, std::pair{"height", height}}) {
    if (side < 0 || side > kMaxJsonImageSide) {
      throw Error(fmt::format("{}: field '{}': expected an integer in [0, {}], got {}", kName, key,
                              kMaxJsonImageSide, side));
    }
  }
  const std::string format_name = JsonString(j, kName, "format");
  PixelFormat format = PixelFormat::kRgb8;
  bool known = false;
  std::string expected;
  for (PixelFormat f : {PixelFormat::kGray8, PixelFormat::kRgb8, PixelFormat::kRgba8,
                        PixelFormat::kGray16, PixelFormat::kFloat32, PixelFormat::kUint32}) {
    expected += (expected.empty() ? "" : ", ") + std::string(ToString(f));
    if (format_name == ToString(f)) {
      format = f;
      known = true;
    }
  }
  if (!known) {
    throw Error(fmt::format("{}: field 'format': expected one of {}, got '{}'", kName, expected,
                            format_name));
  }
  // Every field is checked before the pixels are allocated.
  std::string camera = JsonString(j, kName, "camera");
  const int64_t frame_index = JsonInteger(j, kName, "frame_index");
  const double time = JsonNumber(j, kName, "time");
  auto image = std::make_shared<Image>(static_cast<int>(width), static_cast<int>(height), format);
  image->metadata().camera = std::move(camera);
  image->metadata().frame_index = frame_index;
  image->metadata().time = time;
  return {std::move(image)};
}

}  // namespace saccade::runtime
