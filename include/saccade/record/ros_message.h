#pragma once
// ROS 2 messages read from their serialized form with their definition, as a recording's
// `ros2msg` schema gives it: any type, not only saccade's (a rosbag2 file of another robot's
// topics reads too). The definition is the .msg text of the type followed by those it uses
// (each after a line of '=' and "MSG: pkg/Type", as rosbag2 and saccade write them); the bytes
// are the 4-byte encapsulation header (CDR, either byte order) and XCDR1.
//
//   RosMessageDecoder decoder("sensor_msgs/msg/Image", schema.data);
//   std::vector<std::span<const uint8_t>> blobs;
//   nlohmann::json image = decoder.Decode(message.data, &blobs);
//   // image["width"], image["encoding"], ... ; image["data"] is {"blob": 0}: blobs[0] is the
//   // pixels, in place in the message's bytes
//
// Numbers become JSON numbers (64-bit integers exactly), strings strings, arrays arrays, nested
// messages objects; arrays of uint8, int8, byte and char are not copied into JSON but handed
// back as spans ({"blob": index}).
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

namespace saccade::record {

class RosMessageDecoder {
 public:
  /// Parses the definition of `type` ("sensor_msgs/msg/Image" or "sensor_msgs/Image"). Throws
  /// InvalidArgument naming the type, the line and what is wrong (an unknown field type, a
  /// type used and not defined).
  RosMessageDecoder(const std::string& type, const std::string& definition);
  ~RosMessageDecoder();
  RosMessageDecoder(RosMessageDecoder&&) noexcept;
  RosMessageDecoder& operator=(RosMessageDecoder&&) noexcept;

  /// The message in `cdr`. Byte arrays go to `*blobs` (spans into `cdr`). Throws
  /// InvalidArgument naming the field and the byte when the bytes end before the message does,
  /// or a length is beyond them.
  nlohmann::json Decode(std::span<const uint8_t> cdr,
                        std::vector<std::span<const uint8_t>>* blobs) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saccade::record
