#pragma once
// saccade's messages on ROS 2 topics. A Writer publishes one saccade message type on a ROS
// topic as its ROS 2 type; a Reader subscribes and gives saccade messages back. The message
// types that cross, and what they become (docs/dds.md has the field-by-field mapping):
//
//   saccade message        ROS 2 type on the topic         also
//   image (ImageMessage)   sensor_msgs/Image               sensor_msgs/CameraInfo on the
//                                                          sibling camera_info topic;
//                                                          tf2_msgs/TFMessage world -> the
//                                                          camera's optical frame on /tf
//   head.joints            sensor_msgs/JointState          names pan, tilt, left, right
//   head.command           sensor_msgs/JointState          positions, velocities
//   vision.target          geometry_msgs/PointStamped      frame "world"; only valid targets
//
// Messages carry their capture time as header.stamp (builtin_interfaces/Time: sec, nanosec).
// Frames are named "world" and "<camera>_optical" (OpenCV's camera frame: x right, y down,
// z forward, as ROS's optical frames).
//
// Loss and lateness are counted, never waited out unboundedly: Reader::Take waits at most its
// timeout and reports what it skipped (LinkStats). A writer or reader that goes away and comes
// back is matched again by DDS discovery; a reader sees the restart as a stamp going back and
// counts it.
//
// Thread-safety: one Writer or Reader is used by one thread at a time.
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/dds/participant.h"
#include "saccade/dds/qos.h"
#include "saccade/runtime/message.h"

namespace saccade::dds {

/// Where a message type goes.
struct TopicOptions {
  std::string topic;  ///< fully qualified ROS topic (ResolveTopic), e.g. "/saccade/joint_states"
  Qos qos = Qos::Default();      ///< of the main topic (camera_info and tf: reliable, keep last)
  std::string tf_topic = "/tf";  ///< images: where the camera poses go ("" : none)
  /// Images received: the frame index is round(stamp / frame_period_s) when > 0 (the
  /// sender's clock step), else a count of the frames received.
  double frame_period_s = 0.0;
};

/// What crossed a link, for reports.
struct LinkStats {
  int64_t messages = 0;    ///< written, or taken and handed over
  int64_t lost = 0;        ///< known lost: best-effort gaps and samples overwritten unread
  int64_t late = 0;        ///< Take calls whose wait ended without a new message
  int64_t restarts = 0;    ///< the sender's stamps went back (it restarted)
  int64_t incomplete = 0;  ///< images without camera info or pose (handed over without them)
};

/// The saccade message types that have a ROS 2 form (MessageTraits names: "image", ...).
std::vector<std::string> SupportedMessageTypes();

/// The ROS 2 type a saccade message type is published as ("sensor_msgs/msg/Image"). Throws
/// InvalidArgument naming the type and the supported ones.
std::string RosTypeOf(const std::string& message_type);

/// Publishes one saccade message type on one ROS topic.
class Writer {
 public:
  /// Throws InvalidArgument for an unsupported message type (naming the supported ones), a bad
  /// topic name or QoS; saccade::Error when Cyclone refuses (its reason included).
  static std::unique_ptr<Writer> Create(std::shared_ptr<Participant> participant,
                                        const std::string& message_type,
                                        const TopicOptions& options);
  virtual ~Writer() = default;

  /// Publishes `message` (M must be the writer's type, else InvalidArgument). Does not block
  /// beyond Cyclone's reliable flow control (100 ms at most).
  template <runtime::Message M>
  void Write(const M& message) {
    CheckType(runtime::MessageName<M>());
    WriteErased(&message);
  }
  /// Publishes a message of the writer's type given by address.
  virtual void WriteErased(const void* message) = 0;
  /// Readers matched now.
  virtual int matched() const = 0;
  /// Waits until at least `count` readers match, at most `timeout_s`; true when they do.
  bool WaitForReaders(int count, double timeout_s) const;
  virtual const LinkStats& stats() const = 0;
  const std::string& message_type() const { return message_type_; }
  const std::string& topic() const { return topic_; }

 protected:
  Writer(std::string message_type, std::string topic)
      : message_type_(std::move(message_type)), topic_(std::move(topic)) {}
  void CheckType(const char* name) const;

 private:
  std::string message_type_;
  std::string topic_;
};

/// Subscribes to one ROS topic and gives saccade messages of one type.
class Reader {
 public:
  /// Throws as Writer::Create.
  static std::unique_ptr<Reader> Create(std::shared_ptr<Participant> participant,
                                        const std::string& message_type,
                                        const TopicOptions& options);
  virtual ~Reader() = default;

  /// The newest message that arrived since the last call, waiting for one at most
  /// `timeout_s` (0: do not wait); nullptr when none came (counted late when it waited).
  /// Older messages that arrived in between are skipped and counted lost. The pointer holds
  /// a T of the reader's type (M must be it, else InvalidArgument).
  ///
  /// `up_to` (seconds, a pipeline stepping on the sender's stamps: runtime's clock.source):
  /// the newest message stamped at or before it; messages stamped after it are kept for a
  /// later call (and waiting ends when they arrive), so that a step takes the joints and the
  /// other eye's image of its own time even when the sender is steps ahead. Images are kept
  /// serialized and converted only when handed over, at most 16.
  template <runtime::Message M>
  std::shared_ptr<const M> Take(double timeout_s = 0.0,
                                double up_to = std::numeric_limits<double>::infinity()) {
    CheckType(runtime::MessageName<M>());
    return std::static_pointer_cast<const M>(TakeErased(timeout_s, up_to));
  }
  virtual std::shared_ptr<const void> TakeErased(double timeout_s, double up_to) = 0;
  /// Writers matched now.
  virtual int matched() const = 0;
  /// Waits until at least `count` writers match, at most `timeout_s`; true when they do.
  bool WaitForWriters(int count, double timeout_s) const;
  virtual const LinkStats& stats() const = 0;
  const std::string& message_type() const { return message_type_; }
  const std::string& topic() const { return topic_; }

 protected:
  Reader(std::string message_type, std::string topic)
      : message_type_(std::move(message_type)), topic_(std::move(topic)) {}
  void CheckType(const char* name) const;

 private:
  std::string message_type_;
  std::string topic_;
};

}  // namespace saccade::dds
