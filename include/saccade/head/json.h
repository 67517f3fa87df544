#pragma once
// The JSON codec (core/json_codec.h) of a head's joints: an object of joint name to value, in
// radians (or m, rad/s, as the field that holds them says): {"left": 0.1, "pan": 0, ...}.
// Decoding keeps the names the object has, in its key order (alphabetical); whoever applies it
// to a head arranges it in the head's order by name (JointState::ArrangedAs), which also
// rejects unknown and missing joints.
#include <nlohmann/json.hpp>

#include "saccade/core/json_codec.h"
#include "saccade/head/joint_state.h"

namespace saccade {

template <>
struct JsonCodec<head::JointState> {
  static nlohmann::json Encode(const head::JointState& joints) {
    nlohmann::json out = nlohmann::json::object();
    for (int i = 0; i < joints.size(); ++i) out[joints.name(i)] = joints[i];
    return out;
  }
  static head::JointState Decode(const nlohmann::json& j, const JsonWhere& at) {
    if (!j.is_object()) at.Fail(j, "an object of joint name to number");
    auto names = std::make_shared<head::JointNames>();
    Eigen::VectorXd values(static_cast<Eigen::Index>(j.size()));
    for (const auto& [name, value] : j.items()) {
      if (!value.is_number()) JsonWhere{at.Path(), name}.Fail(value, "a number");
      if (!std::isfinite(value.get<double>())) {
        JsonWhere{at.Path(), name}.Fail(value, "a finite number");
      }
      values[static_cast<Eigen::Index>(names->size())] = value.get<double>();
      names->push_back(name);
    }
    return head::JointState(std::move(names), std::move(values));
  }
};

}  // namespace saccade
