#include "saccade/dds/qos.h"

#include <fmt/format.h>

#include "saccade/core/error.h"

namespace saccade::dds {

Qos Qos::SensorData() { return {Reliability::kBestEffort, Durability::kVolatile, 5}; }
Qos Qos::Default() { return {Reliability::kReliable, Durability::kVolatile, 10}; }
Qos Qos::Images() { return {Reliability::kReliable, Durability::kVolatile, 2}; }
Qos Qos::Latched() { return {Reliability::kReliable, Durability::kTransientLocal, 1}; }

bool Qos::IsValid(std::string* error) const {
  if (depth < 1 || depth > kMaxQosDepth) {
    if (error) *error = fmt::format("depth must be 1..{}, got {}", kMaxQosDepth, depth);
    return false;
  }
  return true;
}

std::string Qos::ToString() const {
  return fmt::format("{}, {}, keep last {}",
                     reliability == Reliability::kReliable ? "reliable" : "best effort",
                     durability == Durability::kVolatile ? "volatile" : "transient local", depth);
}

namespace {

constexpr const char* kProfiles = "sensor_data, default, images, latched";

Qos Profile(const std::string& name, const std::string& where) {
  if (name == "sensor_data") return Qos::SensorData();
  if (name == "default") return Qos::Default();
  if (name == "images") return Qos::Images();
  if (name == "latched") return Qos::Latched();
  throw InvalidArgument(
      fmt::format("{}: unknown QoS profile '{}'; expected one of {}", where, name, kProfiles));
}

std::string Describe(const nlohmann::json& value) { return value.dump(); }

}  // namespace

Qos ParseQos(const nlohmann::json& value, const std::string& where) {
  if (value.is_string()) return Profile(value.get<std::string>(), where);
  if (!value.is_object()) {
    throw InvalidArgument(fmt::format(
        "{}: expected a QoS profile name ({}) or a map {{profile, reliability, durability, "
        "depth}}, got {}",
        where, kProfiles, Describe(value)));
  }
  Qos qos = Qos::Default();
  if (const auto it = value.find("profile"); it != value.end()) {
    if (!it->is_string()) {
      throw InvalidArgument(
          fmt::format("{}.profile: expected one of {}, got {}", where, kProfiles, Describe(*it)));
    }
    qos = Profile(it->get<std::string>(), where + ".profile");
  }
  for (const auto& [key, item] : value.items()) {
    const std::string at = where + "." + key;
    if (key == "profile") continue;
    if (key == "reliability") {
      const std::string text = item.is_string() ? item.get<std::string>() : "";
      if (text == "reliable") {
        qos.reliability = Reliability::kReliable;
      } else if (text == "best_effort") {
        qos.reliability = Reliability::kBestEffort;
      } else {
        throw InvalidArgument(
            fmt::format("{}: expected reliable or best_effort, got {}", at, Describe(item)));
      }
    } else if (key == "durability") {
      const std::string text = item.is_string() ? item.get<std::string>() : "";
      if (text == "volatile") {
        qos.durability = Durability::kVolatile;
      } else if (text == "transient_local") {
        qos.durability = Durability::kTransientLocal;
      } else {
        throw InvalidArgument(
            fmt::format("{}: expected volatile or transient_local, got {}", at, Describe(item)));
      }
    } else if (key == "depth") {
      if (!item.is_number_integer() || item.get<int64_t>() < 1 ||
          item.get<int64_t>() > kMaxQosDepth) {
        throw InvalidArgument(
            fmt::format("{}: expected an integer 1..{}, got {}", at, kMaxQosDepth, Describe(item)));
      }
      qos.depth = item.get<int>();
    } else {
      throw InvalidArgument(fmt::format(
          "{}: unknown QoS key; expected profile, reliability, durability or depth", at));
    }
  }
  return qos;
}

}  // namespace saccade::dds
