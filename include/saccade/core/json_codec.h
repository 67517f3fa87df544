#pragma once
// JSON codecs of value types: one per type, so that joints, points and poses read and write
// the same everywhere (messages, the GUI, the command line's JSON).
//
// JsonCodec<T> has `static nlohmann::json Encode(const T&)` and `static T Decode(const
// nlohmann::json&, const JsonWhere&)`; Decode throws saccade::Error naming where the value
// was: "head.command.positions: field 'tilt': expected a number, got \"up\"". This header
// gives the codecs of bool, integers, numbers, strings and vectors of codec types, and
// structs that list their fields once:
//
//   template <> struct saccade::JsonCodec<head::JointState>
//       : saccade::JsonObjectCodec<head::JointState> {
//     static constexpr auto kFields = std::make_tuple(
//         JsonField("pan", &head::JointState::pan), JsonField("tilt", &head::JointState::tilt));
//   };
//
// A module gives the codecs of its own types (geometry/json.h, head/json.h).

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/core/image.h"

namespace saccade {

/// Where a value sits, for error messages: the path of the object that holds it
/// ("head.command.positions") and its key ("tilt").
struct JsonWhere {
  std::string object;
  std::string key;
  /// The path of this value when it is an object itself: "head.command.positions".
  std::string Path() const { return key.empty() ? object : object + "." + key; }
  /// Throws Error("<object>: field '<key>': expected <what>, got <value>").
  /// ("<object>: expected <what>, got <value>" at the top, where there is no key).
  [[noreturn]] void Fail(const nlohmann::json& value, const std::string& what) const {
    if (key.empty())
      throw Error(fmt::format("{}: expected {}, got {}", object, what, value.dump()));
    throw Error(
        fmt::format("{}: field '{}': expected {}, got {}", object, key, what, value.dump()));
  }
};

template <typename T, typename Enable = void>
struct JsonCodec;

template <>
struct JsonCodec<bool> {
  static nlohmann::json Encode(bool v) { return v; }
  static bool Decode(const nlohmann::json& j, const JsonWhere& at) {
    if (!j.is_boolean()) at.Fail(j, "true or false");
    return j.get<bool>();
  }
};

template <typename T>
struct JsonCodec<T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>>> {
  static nlohmann::json Encode(T v) { return v; }
  static T Decode(const nlohmann::json& j, const JsonWhere& at) {
    if (!j.is_number_integer()) at.Fail(j, "an integer");
    return j.get<T>();
  }
};

template <typename T>
struct JsonCodec<T, std::enable_if_t<std::is_floating_point_v<T>>> {
  static nlohmann::json Encode(T v) { return v; }
  static T Decode(const nlohmann::json& j, const JsonWhere& at) {
    if (!j.is_number()) at.Fail(j, "a number");
    return j.get<T>();
  }
};

template <>
struct JsonCodec<std::string> {
  static nlohmann::json Encode(const std::string& v) { return v; }
  static std::string Decode(const nlohmann::json& j, const JsonWhere& at) {
    if (!j.is_string()) at.Fail(j, "a string");
    return j.get<std::string>();
  }
};

/// A list; element i of field `key` decodes at "<object>.<key>[i]".
template <typename T>
struct JsonCodec<std::vector<T>> {
  static nlohmann::json Encode(const std::vector<T>& v) {
    nlohmann::json out = nlohmann::json::array();
    for (const T& item : v) out.push_back(JsonCodec<T>::Encode(item));
    return out;
  }
  static std::vector<T> Decode(const nlohmann::json& j, const JsonWhere& at) {
    if (!j.is_array()) at.Fail(j, "an array");
    std::vector<T> out;
    out.reserve(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) {
      out.push_back(JsonCodec<T>::Decode(j[i], {at.object, fmt::format("{}[{}]", at.key, i)}));
    }
    return out;
  }
};

/// A value that may be absent: null (or a missing field) for none.
template <typename T>
struct JsonCodec<std::optional<T>> {
  static constexpr bool kOptional = true;
  static nlohmann::json Encode(const std::optional<T>& v) {
    return v ? JsonCodec<T>::Encode(*v) : nlohmann::json(nullptr);
  }
  static std::optional<T> Decode(const nlohmann::json& j, const JsonWhere& at) {
    if (j.is_null()) return std::nullopt;
    return JsonCodec<T>::Decode(j, at);
  }
};

/// One field of a struct S: its JSON key and its member.
template <typename S, typename T>
struct JsonFieldOf {
  const char* name;
  T S::*member;
};
template <typename S, typename T>
constexpr JsonFieldOf<S, T> JsonField(const char* name, T S::*member) {
  return {name, member};
}

/// The value of field `key` of the object `j` at path `object`, decoded as T. Throws
/// "<object>: expected a JSON object, got ..." or "<object>: missing field '<key>'" (unless
/// the codec says `kOptional`: then a missing field is T{}).
template <typename T>
T DecodeField(const nlohmann::json& j, const std::string& object, const char* key) {
  if (!j.is_object()) {
    throw Error(fmt::format("{}: expected a JSON object, got {}", object, j.dump()));
  }
  const auto it = j.find(key);
  if (it == j.end()) {
    if constexpr (requires { JsonCodec<T>::kOptional; }) return T{};
    throw Error(fmt::format("{}: missing field '{}'", object, key));
  }
  return JsonCodec<T>::Decode(*it, {object, key});
}

/// {name: Encode(member), ...} for a tuple of JsonFieldOf.
template <typename S, typename Fields>
nlohmann::json EncodeFields(const S& s, const Fields& fields) {
  nlohmann::json out = nlohmann::json::object();
  std::apply(
      [&](const auto&... f) {
        ((out[f.name] = JsonCodec<std::decay_t<decltype(s.*(f.member))>>::Encode(s.*(f.member))),
         ...);
      },
      fields);
  return out;
}

/// Sets every listed member of a default S from the object `j` at path `object`; each field
/// is required.
template <typename S, typename Fields>
S DecodeFields(const nlohmann::json& j, const std::string& object, const Fields& fields) {
  S s{};
  std::apply(
      [&](const auto&... f) {
        ((s.*(f.member) = DecodeField<std::decay_t<decltype(s.*(f.member))>>(j, object, f.name)),
         ...);
      },
      fields);
  return s;
}

/// The codec of a struct that lists its fields as JsonCodec<S>::kFields (file comment).
template <typename S>
struct JsonObjectCodec {
  static nlohmann::json Encode(const S& s) { return EncodeFields(s, JsonCodec<S>::kFields); }
  static S Decode(const nlohmann::json& j, const JsonWhere& at) {
    return DecodeFields<S>(j, at.Path(), JsonCodec<S>::kFields);
  }
};

/// An image in a message: its metadata only, {camera, frame_index, time} (null for none);
/// pixels never go into text. Decodes to no image, and may be absent.
template <>
struct JsonCodec<std::shared_ptr<const Image>> {
  static constexpr bool kOptional = true;
  static nlohmann::json Encode(const std::shared_ptr<const Image>& image) {
    if (!image) return nullptr;
    const ImageMetadata& meta = image->metadata();
    return {{"camera", meta.camera}, {"frame_index", meta.frame_index}, {"time", meta.time}};
  }
  static std::shared_ptr<const Image> Decode(const nlohmann::json&, const JsonWhere&) {
    return nullptr;
  }
};

/// Shorthands.
template <typename T>
nlohmann::json ToJson(const T& value) {
  return JsonCodec<T>::Encode(value);
}
template <typename T>
T FromJson(const nlohmann::json& j, const std::string& what) {
  return JsonCodec<T>::Decode(j, {what, ""});
}

}  // namespace saccade
