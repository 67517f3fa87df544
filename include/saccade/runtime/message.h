#pragma once
// Messages: every type that travels on the bus has a name and a JSON form (DESIGN.md), for
// the browser link and a later distributed transport. In one process messages are never
// serialised; JSON is only for crossing a process boundary.
//
// A module makes its type a message by specialising MessageTraits:
//
//   template <> struct saccade::runtime::MessageTraits<my::Target> {
//     static constexpr const char* kName = "vision.target";
//     static nlohmann::json ToJson(const my::Target& m);
//     static my::Target FromJson(const nlohmann::json& j);  // throws saccade::Error
//   };
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
#include <vector>

#include "saccade/core/error.h"
#include "saccade/core/image.h"

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

/// Reads a required field of a JSON object, naming the message type and field on error.
/// Throws saccade::Error ("<type>: field '<key>': expected <what>").
const nlohmann::json& JsonField(const nlohmann::json& json, const char* type, const char* key);
/// A required field of the given kind; throws saccade::Error as JsonField, naming what was got.
double JsonNumber(const nlohmann::json& json, const char* type, const char* key);
int64_t JsonInteger(const nlohmann::json& json, const char* type, const char* key);
bool JsonBool(const nlohmann::json& json, const char* type, const char* key);
std::string JsonString(const nlohmann::json& json, const char* type, const char* key);
/// A required array of exactly `n` numbers.
std::vector<double> JsonNumbers(const nlohmann::json& json, const char* type, const char* key,
                                std::size_t n);

template <>
struct MessageTraits<Tick> {
  static constexpr const char* kName = "runtime.tick";
  static nlohmann::json ToJson(const Tick& m);
  static Tick FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<Value> {
  static constexpr const char* kName = "runtime.value";
  static nlohmann::json ToJson(const Value& m);
  static Value FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<Empty> {
  static constexpr const char* kName = "runtime.empty";
  static nlohmann::json ToJson(const Empty& m);
  static Empty FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<Text> {
  static constexpr const char* kName = "runtime.text";
  static nlohmann::json ToJson(const Text& m);
  static Text FromJson(const nlohmann::json& j);
};

template <>
struct MessageTraits<ImageMessage> {
  static constexpr const char* kName = "runtime.image";
  static nlohmann::json ToJson(const ImageMessage& m);
  static ImageMessage FromJson(const nlohmann::json& j);
};

}  // namespace saccade::runtime
