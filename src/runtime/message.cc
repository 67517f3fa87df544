#include "saccade/runtime/message.h"

#include <fmt/format.h>

#include <utility>

namespace saccade::runtime {
namespace {

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

nlohmann::json MessageTraits<Empty>::ToJson(const Empty&) { return nlohmann::json::object(); }

Empty MessageTraits<Empty>::FromJson(const nlohmann::json& j) {
  if (!j.is_null() && !(j.is_object() && j.empty())) {
    throw Error(fmt::format("{}: expected {{}}, got {}", kName, j.dump()));
  }
  return {};
}

nlohmann::json MessageTraits<ImageMessage>::ToJson(const ImageMessage& m) {
  if (!m.image) return nullptr;
  const Image& image = *m.image;
  const ImageMetadata& meta = image.metadata();
  // Metadata only: pixels never go into text (DESIGN.md).
  // With the camera controls the frame was taken with (ImageMetadata: 0 s an instant, 0 m
  // none given), as frames.jsonl writes them.
  return {{"camera", meta.camera},
          {"frame_index", meta.frame_index},
          {"time", meta.time},
          {"width", image.width()},
          {"height", image.height()},
          {"format", ToString(image.format())},
          {"exposure_s", meta.exposure_s},
          {"gain_db", meta.gain_db},
          {"focus_m", meta.focus_m}};
}

ImageMessage MessageTraits<ImageMessage>::FromJson(const nlohmann::json& j) {
  if (j.is_null()) return {};
  const int64_t width = DecodeField<int64_t>(j, kName, "width");
  const int64_t height = DecodeField<int64_t>(j, kName, "height");
  for (const auto& [key, side] : {std::pair{"width", width}, std::pair{"height", height}}) {
    if (side < 0 || side > kMaxJsonImageSide) {
      throw Error(fmt::format("{}: field '{}': expected an integer in [0, {}], got {}", kName, key,
                              kMaxJsonImageSide, side));
    }
  }
  const std::string format_name = DecodeField<std::string>(j, kName, "format");
  PixelFormat format = PixelFormat::kRgb8;
  bool known = false;
  std::string expected;
  for (PixelFormat f :
       {PixelFormat::kGray8, PixelFormat::kRgb8, PixelFormat::kRgba8, PixelFormat::kGray16,
        PixelFormat::kFloat32, PixelFormat::kUint32, PixelFormat::kBayerRggb8,
        PixelFormat::kBayerBggr8, PixelFormat::kBayerGbrg8, PixelFormat::kBayerGrbg8,
        PixelFormat::kBayerRggb16, PixelFormat::kBayerBggr16, PixelFormat::kBayerGbrg16,
        PixelFormat::kBayerGrbg16}) {
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
  std::string camera = DecodeField<std::string>(j, kName, "camera");
  const int64_t frame_index = DecodeField<int64_t>(j, kName, "frame_index");
  const double time = DecodeField<double>(j, kName, "time");
  // The camera controls: optional (absent or null: 0, as ImageMetadata's "none").
  double controls[3] = {0.0, 0.0, 0.0};
  const char* const control_keys[3] = {"exposure_s", "gain_db", "focus_m"};
  for (int i = 0; i < 3; ++i) {
    const auto it = j.find(control_keys[i]);
    if (it != j.end() && !it->is_null())
      controls[i] = DecodeField<double>(j, kName, control_keys[i]);
  }
  auto image = std::make_shared<Image>(static_cast<int>(width), static_cast<int>(height), format);
  image->metadata().camera = std::move(camera);
  image->metadata().frame_index = frame_index;
  image->metadata().time = time;
  image->metadata().exposure_s = controls[0];
  image->metadata().gain_db = controls[1];
  image->metadata().focus_m = controls[2];
  return {std::move(image)};
}

}  // namespace saccade::runtime
