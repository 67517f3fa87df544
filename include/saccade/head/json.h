#pragma once
// The JSON codec (core/json_codec.h) of a head's joints: {pan, tilt, left, right} in radians
// (or rad/s, as the field that holds them says).
#include <tuple>

#include "saccade/core/json_codec.h"
#include "saccade/head/head_description.h"

namespace saccade {

template <>
struct JsonCodec<head::JointState> : JsonObjectCodec<head::JointState> {
  static constexpr auto kFields = std::make_tuple(
      JsonField("pan", &head::JointState::pan), JsonField("tilt", &head::JointState::tilt),
      JsonField("left", &head::JointState::left), JsonField("right", &head::JointState::right));
};

}  // namespace saccade
