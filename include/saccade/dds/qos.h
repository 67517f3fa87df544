#pragma once
// Quality of service of one DDS topic, in ROS 2's terms (rmw's QoS profiles): reliability,
// durability and the history depth (keep last N). Cyclone's own QoS objects stay private to
// the module (src/dds/).
//
// The profiles (rclcpp's qos_profile_sensor_data and rmw_qos_profile_default):
//   sensor_data  best effort, volatile, keep last 5
//   default      reliable, volatile, keep last 10
//   images       reliable, volatile, keep last 2: a lost fragment loses a whole best-effort
//                image (a 1024x768 RGB image is ~40 loopback packets), so images default to
//                reliable with a short history (the receiver wants the newest). Image
//                writers offer transient local whatever their QoS says (keeping their last
//                `depth` images for readers that come later and ask for them: a perception
//                started after the robot's first step); volatile readers match them as well
//   latched      reliable, transient local, keep last 1: a late-joining reader gets the
//                newest sample (the head's state, camera info)
#include <nlohmann/json.hpp>
#include <string>

namespace saccade::dds {

enum class Reliability { kBestEffort, kReliable };
enum class Durability { kVolatile, kTransientLocal };

/// Largest history depth a topic may keep (guards memory: each kept image is megabytes).
inline constexpr int kMaxQosDepth = 1000;

/// A topic's QoS. A small copyable value; IsValid checks it.
struct Qos {
  Reliability reliability = Reliability::kReliable;
  Durability durability = Durability::kVolatile;
  int depth = 10;  ///< keep last `depth` samples, 1..kMaxQosDepth

  static Qos SensorData();
  static Qos Default();
  static Qos Images();
  static Qos Latched();

  /// False (and `*error` says why) when depth is out of range.
  bool IsValid(std::string* error = nullptr) const;
  /// "reliable, volatile, keep last 10".
  std::string ToString() const;
  bool operator==(const Qos&) const = default;
};

/// A QoS from a pipeline file or the command line: a profile name ("sensor_data", "default",
/// "images", "latched") or a map {profile, reliability: reliable | best_effort, durability:
/// volatile | transient_local, depth: N} whose keys override the profile's (default
/// "default"). Throws InvalidArgument starting with `where` and naming the bad key, the value
/// got and the values expected.
Qos ParseQos(const nlohmann::json& value, const std::string& where);

}  // namespace saccade::dds
