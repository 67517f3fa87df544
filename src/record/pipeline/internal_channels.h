#pragma once
// The channels of a recording: one per topic, made on its first message, with its ROS 2
// type's ros2msg schema (one per type) for CDR, or none for JSON. Shared by the pipeline's
// recorder and the render command's (recorder.h, frame_recorder.h).
#include <cmath>
#include <cstdint>
#include <map>
#include <string>

#include "saccade/core/error.h"
#include "saccade/dds/topics.h"
#include "saccade/record/mcap.h"
#include "saccade/record/recorder.h"

namespace saccade::record::internal {

/// The writer's options for a recorder's; InvalidArgument for options out of range.
inline McapWriterOptions WriterOptions(const RecorderOptions& o) {
  if (o.compression != "zstd" && o.compression != "none") {
    throw InvalidArgument("record: compression must be zstd or none, got '" + o.compression + "'");
  }
  if (!(o.chunk_seconds > 0.0) || !std::isfinite(o.chunk_seconds)) {
    throw InvalidArgument("record: chunk seconds must be > 0, got " +
                          std::to_string(o.chunk_seconds));
  }
  McapWriterOptions w;
  w.compression = o.compression == "none" ? "" : o.compression;
  w.chunk_seconds = o.chunk_seconds;
  w.zstd_level = o.zstd_level;
  w.chunk_bytes = 8 << 20;
  return w;
}

/// A run's time as a log time: ns, 0 for times before the start.
inline uint64_t Nanoseconds(double seconds) {
  return seconds <= 0.0 || !std::isfinite(seconds)
             ? 0
             : static_cast<uint64_t>(std::llround(seconds * 1e9));
}

class Channels {
 public:
  explicit Channels(McapWriter& writer) : writer_(writer) {}

  /// The channel of `topic`: CDR of `ros_type`, or JSON when `ros_type` is "".
  uint16_t Of(const std::string& topic, const std::string& ros_type) {
    if (const auto found = channels_.find(topic); found != channels_.end()) return found->second;
    uint16_t schema = 0;
    if (!ros_type.empty()) {
      auto [at, added] = schemas_.try_emplace(ros_type, 0);
      if (added) {
        at->second = writer_.AddSchema(ros_type, "ros2msg", dds::RosMessageDefinition(ros_type));
      }
      schema = at->second;
    }
    const uint16_t id = writer_.AddChannel(schema, topic, ros_type.empty() ? "json" : "cdr");
    channels_[topic] = id;
    return id;
  }

  /// A serialized ROS 2 message (dds::Writer::CreateSerializing's sink), logged at `log_time`;
  /// its capture stamp is its publish time.
  void Write(const dds::SerializedMessage& m, uint64_t log_time) {
    writer_.Write(Of(m.topic, m.ros_type), log_time,
                  static_cast<uint64_t>(m.stamp_ns < 0 ? 0 : m.stamp_ns), {m.data, m.size});
  }

 private:
  McapWriter& writer_;
  std::map<std::string, uint16_t> schemas_;   // by ROS type
  std::map<std::string, uint16_t> channels_;  // by topic
};

}  // namespace saccade::record::internal
