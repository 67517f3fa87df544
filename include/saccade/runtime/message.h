#pragma once
// Messages: every type that travels on the bus has a name and a JSON form (DESIGN.md), for
// the browser link and a later distributed transport. In one process messages are never
// serialised; JSON is only for crossing a process boundary.
//
// A module makes its type a message by specialising MessageTraits with its name and its
// fields, each listed once; the JSON form follows (core/json_codec.h gives the codec of each
// field's type):
//
//   template <> struct saccade::runtime::MessageTraits<my::Target>
//       : saccade::runtime::FieldMessage<my::Target> {
//     static constexpr const char* kName = "vision.target";
//     static constexpr auto kFields = std::make_tuple(
//         JsonField("time", &my::Target::time), JsonField("p_W", &my::Target::p_W));
//   };
//
// (A type with a form of its own gives static ToJson and FromJson instead; FromJson throws
// saccade::Error naming the message type and the field.)
//
// and, to let type-erased code (the server) find it by name, registers it once:
// MessageRegistry::Global().Register<my::Target>().

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/core/image.h"
#include "saccade/core/json_codec.h"

namespace saccade::runtime {

/// Specialise for each message type: kName, ToJson, FromJson (see the file comment).
template <typename T>
struct MessageTraits;

/// A type with a MessageTraits specialisation.
template <typename T>
concept Message = requires(const T& message, const nlohmann::json& json) {
  { MessageTraits<T>::kName } -> std::convertible_to<const char*>;
  { MessageTraits<T>::ToJson(message) } -> std::convertible_to<nlohmann::json>;
  { MessageTraits<T>::FromJson(json) } -> std::convertible_to<T>;
};

/// The message type's name ("runtime.tick").
template <Message T>
const char* MessageName() {
  return MessageTraits<T>::kName;
}

/// ToJson and FromJson of a message that lists its fields as MessageTraits<M>::kFields (the
/// file comment). Every field is required in FromJson, except images (metadata only).
template <typename M>
struct FieldMessage {
  static nlohmann::json ToJson(const M& m) { return EncodeFields(m, MessageTraits<M>::kFields); }
  static M FromJson(const nlohmann::json& j) {
    return DecodeFields<M>(j, MessageTraits<M>::kName, MessageTraits<M>::kFields);
  }
};

/// Type-erased JSON conversion of one message type, as the registry holds it.
struct MessageType {
  std::string name;
  /// `message` points to a T.
  std::function<nlohmann::json(const void* message)> to_json;
  /// Returns a new T; throws saccade::Error when the JSON is not a valid T.
  std::function<std::shared_ptr<const void>(const nlohmann::json& json)> from_json;
};

/// The message types known by name. Modules register theirs at start-up (not thread-safe:
/// register before running pipelines).
class MessageRegistry {
 public:
  /// The process-wide registry; holds the runtime's own types from the start.
  static MessageRegistry& Global();

  /// Registers T under MessageTraits<T>::kName. Registering a name again keeps the first
  /// registration, so that modules may register idempotently.
  template <Message T>
  void Register() {
    Add(MessageType{MessageTraits<T>::kName,
                    [](const void* message) {
                      return MessageTraits<T>::ToJson(*static_cast<const T*>(message));
                    },
                    [](const nlohmann::json& json) -> std::shared_ptr<const void> {
                      return std::make_shared<const T>(MessageTraits<T>::FromJson(json));
                    }});
  }

  /// nullptr when unknown.
  const MessageType* Find(const std::string& name) const;
  /// Registered names, sorted.
  std::vector<std::string> Names() const;

 private:
  void Add(MessageType type);
  std::map<std::string, MessageType> types_;
};

/// {"type": name, "data": ToJson(message)}: the envelope used on text links.
template <Message T>
nlohmann::json ToEnvelope(const T& message) {
  return {{"type", MessageTraits<T>::kName}, {"data", MessageTraits<T>::ToJson(message)}};
}

// ---- The runtime's own message types ---------------------------------------------------

/// One scheduler tick: the step index and the time (s) at its start.
struct Tick {
  int64_t step = 0;
  double time = 0.0;
  bool operator==(const Tick&) const = default;
};

/// A single number (a gain, a measured value, a random draw).
struct Value {
  double value = 0.0;
  bool operator==(const Value&) const = default;
};

/// A short text (a status, a command).
struct Text {
  std::string text;
  bool operator==(const Text&) const = default;
};

/// No content: the request of a method that takes no argument. JSON: {} (or null).
struct Empty {
  bool operator==(const Empty&) const = default;
};

/// A frame, shared: every receiver holds the same pixels. Its JSON form carries metadata
/// only (camera, frame index, time, width, height, format), never pixels; FromJson gives a
/// zero-filled image of that size with that metadata (each side at most kMaxJsonImageSide).
struct ImageMessage {
  std::shared_ptr<const Image> image;
};

/// Largest width or height FromJson accepts for an ImageMessage (guards the allocation).
inline constexpr int kMaxJsonImageSide = 16384;

template <>
struct MessageTraits<Tick> : FieldMessage<Tick> {
  static constexpr const char* kName = "runtime.tick";
  static constexpr auto kFields =
      std::make_tuple(JsonField("step", &Tick::step), JsonField("time", &Tick::time));
};

template <>
struct MessageTraits<Value> : FieldMessage<Value> {
  static constexpr const char* kName = "runtime.value";
  static constexpr auto kFields = std::make_tuple(JsonField("value", &Value::value));
};

template <>
struct MessageTraits<Empty> {
  static constexpr const char* kName = "runtime.empty";
  static nlohmann::json ToJson(const Empty& m);
  static Empty FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<Text> : FieldMessage<Text> {
  static constexpr const char* kName = "runtime.text";
  static constexpr auto kFields = std::make_tuple(JsonField("text", &Text::text));
};

template <>
struct MessageTraits<ImageMessage> {
  static constexpr const char* kName = "runtime.image";
  static nlohmann::json ToJson(const ImageMessage& m);
  static ImageMessage FromJson(const nlohmann::json& j);
};

}  // namespace saccade::runtime
