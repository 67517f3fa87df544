#include "saccade/dds/topics.h"

#include <dds/ddsi/ddsi_cdrstream.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <string_view>
#include <thread>
#include <type_traits>

#include "dds/internal_convert.h"
#include "dds/internal_cyclone.h"
#include "saccade/components/messages.h"
#include "saccade/core/log.h"
#include "saccade/dds/topic_names.h"
#include "saccade/geometry/image_camera.h"

namespace saccade::dds {

using components::JointCommand;
using components::JointStateMessage;
using components::MapMessage;
using components::TargetMessage;
using runtime::ImageMessage;
using runtime::MessageName;

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr int kMaxTake = 32;  // samples taken at once: older ones are skipped (counted lost)

// Cyclone's QoS for `qos` (XCDR1 explicitly: the only representation rmw_cyclonedds reads).
dds_qos_t* MakeQos(const Qos& qos) {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q,
                       qos.reliability == Reliability::kReliable ? DDS_RELIABILITY_RELIABLE
                                                                 : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_MSECS(100));
  dds_qset_durability(q, qos.durability == Durability::kVolatile ? DDS_DURABILITY_VOLATILE
                                                                 : DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, qos.depth);
  // A transient-local writer keeps for readers that come later what its durability service's
  // history says, not its own history (Cyclone's default: the last 1): the same depth, as
  // rmw_cyclonedds sets it.
  dds_qset_durability_service(q, 0, DDS_HISTORY_KEEP_LAST, qos.depth, DDS_LENGTH_UNLIMITED,
                              DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(q, 1, &xcdr1);
  return q;
}

// A Cyclone entity deleted with its owner.
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    std::swap(handle_, other.handle_);
    return *this;
  }
  ~Entity() {
    if (handle_ > 0) dds_delete(handle_);
  }
  dds_entity_t get() const { return handle_; }

 private:
  dds_entity_t handle_ = 0;
};

Entity MakeTopic(const Participant& participant, const dds_topic_descriptor_t* descriptor,
                 const std::string& ros_topic) {
  const std::string name = DdsTopicName(ros_topic);
  return Entity(internal::Check(
      dds_create_topic(participant.handle(), descriptor, name.c_str(), nullptr, nullptr),
      fmt::format("dds: cannot create topic {} ({})", name, descriptor->m_typename)));
}

// What a lockstep writer puts in its DDS user data (TopicOptions::lockstep), and a writer whose
// stamps carry an offset (TopicOptions::stamp_offset_ns), in ROS 2's "key=value;" form.
constexpr char kLockstepUserData[] = "saccade.lockstep=1;";
constexpr char kStampOffsetKey[] = "saccade.stamp_offset_ns=";
// A step mark within this of the step's time is the step's (stamps are whole nanoseconds).
constexpr double kStepMargin = 1e-6;

Entity MakeWriter(const Participant& participant, const Entity& topic, const Qos& qos,
                  const std::string& what, bool lockstep = false, int64_t stamp_offset_ns = 0) {
  dds_qos_t* q = MakeQos(qos);
  std::string user_data = lockstep ? kLockstepUserData : "";
  if (stamp_offset_ns != 0) user_data += fmt::format("{}{};", kStampOffsetKey, stamp_offset_ns);
  if (!user_data.empty()) dds_qset_userdata(q, user_data.data(), user_data.size());
  const dds_entity_t writer = dds_create_writer(participant.handle(), topic.get(), q, nullptr);
  dds_delete_qos(q);
  return Entity(internal::Check(writer, "dds: cannot create the writer of " + what));
}

Entity MakeReader(const Participant& participant, const Entity& topic, const Qos& qos,
                  const std::string& what) {
  dds_qos_t* q = MakeQos(qos);
  const dds_entity_t reader = dds_create_reader(participant.handle(), topic.get(), q, nullptr);
  dds_delete_qos(q);
  return Entity(internal::Check(reader, "dds: cannot create the reader of " + what));
}

int PublicationMatches(const Entity& writer) {
  dds_publication_matched_status_t status{};
  if (dds_get_publication_matched_status(writer.get(), &status) < 0) return 0;
  return static_cast<int>(status.current_count);
}

int SubscriptionMatches(const Entity& reader) {
  dds_subscription_matched_status_t status{};
  if (dds_get_subscription_matched_status(reader.get(), &status) < 0) return 0;
  return static_cast<int>(status.current_count);
}

bool WaitUntil(double timeout_s, const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!done()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

// Writes `sample`, logging (not throwing: a per-frame path) when Cyclone refuses.
void WriteSample(const Entity& writer, const void* sample, const std::string& topic,
                 LinkStats& stats) {
  const dds_return_t rc = dds_write(writer.get(), sample);
  if (rc < 0) {
    ++stats.lost;
    log::Log(log::Level::kWarn, "dds: writing {} failed: {}", topic, dds_strretcode(rc));
  }
}

// ---- outlets: where a writer's samples go --------------------------------------------------

// One topic of a writer: a DDS writer on it, or its samples serialized for a recording
// (Writer::CreateSerializing). The writers below fill samples the same way for both.
class Outlet {
 public:
  virtual ~Outlet() = default;
  // Writes `sample` (of the outlet's type), captured at `stamp_ns` (its header's stamp).
  virtual void Write(const void* sample, int64_t stamp_ns, LinkStats& stats) = 0;
  // Readers matched now; a serializing outlet's sink counts as one.
  virtual int matched() const = 0;
};

class DdsOutlet final : public Outlet {
 public:
  DdsOutlet(const Participant& participant, const dds_topic_descriptor_t* descriptor,
            const std::string& ros_topic, const Qos& qos, bool lockstep, int64_t offset)
      : topic_name_(ros_topic),
        topic_(MakeTopic(participant, descriptor, ros_topic)),
        writer_(MakeWriter(participant, topic_, qos, ros_topic, lockstep, offset)) {}
  void Write(const void* sample, int64_t, LinkStats& stats) override {
    WriteSample(writer_, sample, topic_name_, stats);
  }
  int matched() const override { return PublicationMatches(writer_); }

 private:
  std::string topic_name_;
  Entity topic_, writer_;
};

class SerializingOutlet final : public Outlet {
 public:
  SerializingOutlet(const dds_topic_descriptor_t* descriptor, std::string ros_topic,
                    SerializedSink sink)
      : descriptor_(descriptor),
        topic_(std::move(ros_topic)),
        ros_type_(internal::RosTypeName(descriptor->m_typename)),
        sink_(std::move(sink)) {}
  void Write(const void* sample, int64_t stamp_ns, LinkStats&) override {
    const std::span<const uint8_t> bytes = serializer_.Serialize(*descriptor_, sample);
    sink_({topic_, ros_type_, stamp_ns, bytes.data(), bytes.size()});
  }
  int matched() const override { return 1; }

 private:
  const dds_topic_descriptor_t* descriptor_;
  std::string topic_;
  std::string ros_type_;
  SerializedSink sink_;
  internal::CdrSerializer serializer_;  // its buffer reused from message to message
};

// Makes a writer's outlets: (descriptor, ROS topic, QoS, lockstep) -> the outlet.
using OutletFactory = std::function<std::unique_ptr<Outlet>(const dds_topic_descriptor_t*,
                                                            const std::string&, const Qos&, bool)>;

OutletFactory DdsOutlets(std::shared_ptr<Participant> participant, int64_t offset) {
  return [participant = std::move(participant), offset](const dds_topic_descriptor_t* descriptor,
                                                        const std::string& topic, const Qos& qos,
                                                        bool lockstep) {
    return std::make_unique<DdsOutlet>(*participant, descriptor, topic, qos, lockstep, offset);
  };
}

OutletFactory SerializingOutlets(SerializedSink sink) {
  return [sink = std::move(sink)](const dds_topic_descriptor_t* descriptor,
                                  const std::string& topic, const Qos&, bool) {
    return std::make_unique<SerializingOutlet>(descriptor, topic, sink);
  };
}

// Takes every sample there is from `reader` (loaned), calls `each(sample, info)` on the
// valid ones in arrival order, returns the count of valid samples.
template <typename Sample, typename Each>
int TakeAll(const Entity& reader, Each each) {
  int valid = 0;
  for (;;) {
    void* samples[kMaxTake] = {nullptr};
    dds_sample_info_t infos[kMaxTake];
    const dds_return_t n = dds_take(reader.get(), samples, infos, kMaxTake, kMaxTake);
    if (n <= 0) break;
    for (dds_return_t i = 0; i < n; ++i) {
      if (infos[i].valid_data) {
        each(*static_cast<const Sample*>(samples[i]), infos[i]);
        ++valid;
      }
    }
    dds_return_loan(reader.get(), samples, n);
    if (n < kMaxTake) break;
  }
  return valid;
}

// Counts what DDS reports lost (best-effort gaps) since the last call.
int64_t LostSince(const Entity& reader) {
  dds_sample_lost_status_t status{};
  if (dds_get_sample_lost_status(reader.get(), &status) < 0) return 0;
  return status.total_count_change;
}

// A waitset on "data available" of one reader.
class DataWait {
 public:
  explicit DataWait(const Entity& reader) {
    waitset_ = Entity(internal::Check(dds_create_waitset(DDS_CYCLONEDDS_HANDLE), "dds: waitset"));
    condition_ = Entity(internal::Check(dds_create_readcondition(reader.get(), DDS_ANY_STATE),
                                        "dds: read condition"));
    internal::Check(dds_waitset_attach(waitset_.get(), condition_.get(), 0), "dds: attach");
  }
  void Wait(double timeout_s) {
    if (timeout_s <= 0) return;
    dds_waitset_wait(waitset_.get(), nullptr, 0, static_cast<dds_duration_t>(timeout_s * 1e9));
  }

 private:
  Entity waitset_;
  Entity condition_;
};

// What each writer matched by a reader announces in its user data (MakeWriter), asked once per
// writer: whether it is in lockstep, and the offset of its stamps.
class Announcements {
 public:
  struct Of {
    bool lockstep = false;
    int64_t stamp_offset_ns = 0;
  };
  const Of& Get(const Entity& reader, dds_instance_handle_t writer) {
    const auto it = known_.find(writer);
    if (it != known_.end()) return it->second;
    Of of;
    bool found = false;
    if (dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(reader.get(), writer)) {
      found = true;
      void* data = nullptr;
      size_t size = 0;
      if (e->qos && dds_qget_userdata(e->qos, &data, &size) && data != nullptr) {
        const std::string text(static_cast<const char*>(data), size);
        of.lockstep = text.find(kLockstepUserData) != std::string::npos;
        if (const auto at = text.find(kStampOffsetKey); at != std::string::npos) {
          of.stamp_offset_ns =
              std::strtoll(text.c_str() + at + sizeof(kStampOffsetKey) - 1, nullptr, 10);
        }
      }
      dds_free(data);
      dds_builtintopic_free_endpoint(e);
    }
    if (!found) {  // not matched (any more): asked again next time
      scratch_ = of;
      return scratch_;
    }
    return known_.emplace(writer, of).first->second;
  }

 private:
  std::map<dds_instance_handle_t, Of> known_;
  Of scratch_;
};

// ---- writers -------------------------------------------------------------------------------

class ImageWriter final : public Writer {
 public:
  ImageWriter(OutletFactory make, const TopicOptions& options)
      : Writer(MessageName<ImageMessage>(), options.topic),
        make_(std::move(make)),
        offset_(options.stamp_offset_ns),
        compressed_format_(options.compressed_format),
        jpeg_quality_(options.jpeg_quality) {
    // Transient local whatever the QoS: the writer keeps its last images for readers that come
    // later and ask for them (a perception started after the robot's first step gets that
    // step's images); every reader, volatile or not, matches it.
    Qos qos = options.qos;
    qos.durability = Durability::kTransientLocal;
    image_ = make_(&sensor_msgs_msg_dds__Image__desc, options.topic, qos, false);
    info_ = make_(&sensor_msgs_msg_dds__CameraInfo__desc,
                  SiblingTopic(options.topic, "camera_info"), Qos::Latched(), false);
    if (!options.tf_topic.empty()) {
      // ROS 2's tf QoS (reliable, keep last 100), transient local as the images: a reader of
      // the images' history gets their poses too (ROS's volatile readers match).
      tf_ = make_(&tf2_msgs_msg_dds__TFMessage__desc, options.tf_topic,
                  {Reliability::kReliable, Durability::kTransientLocal, 100}, false);
    }
    if (!compressed_format_.empty()) {
      compressed_topic_name_ = options.topic + "/compressed";
      compressed_ =
          make_(&sensor_msgs_msg_dds__CompressedImage__desc, compressed_topic_name_, qos, false);
    }
  }

  void WriteErased(const void* message) override {
    const auto& m = *static_cast<const ImageMessage*>(message);
    if (!m.image) return;
    const Image& image = *m.image;
    internal::Holder holder;
    // Pose and camera info first, so that a reader has them when the image arrives.
    if (tf_) {
      geometry_msgs_msg_dds__TransformStamped_ transform{};
      if (internal::FillCameraTransform(image, holder, &transform)) {
        tf2_msgs_msg_dds__TFMessage_ tf{};
        transform.header.stamp = internal::ShiftStamp(transform.header.stamp, offset_);
        tf.transforms = {1, 1, &transform, false};
        tf_->Write(&tf, internal::StampNs(transform.header.stamp), stats_);
      }
    }
    sensor_msgs_msg_dds__CameraInfo_ info{};
    if (internal::FillCameraInfo(image, holder, &info)) {
      info.header.stamp = internal::ShiftStamp(info.header.stamp, offset_);
      info_->Write(&info, internal::StampNs(info.header.stamp), stats_);
    }
    sensor_msgs_msg_dds__Image_ msg{};
    if (!internal::FillImage(image, holder, &msg)) {
      throw InvalidArgument(fmt::format("dds: {} images have no sensor_msgs/Image encoding ({})",
                                        ToString(image.format()), topic()));
    }
    msg.header.stamp = internal::ShiftStamp(msg.header.stamp, offset_);
    image_->Write(&msg, internal::StampNs(msg.header.stamp), stats_);
    ++stats_.messages;
    // Compressed only for a reader of it: encoding costs milliseconds an image.
    if (compressed_ && compressed_->matched() > 0) {
      internal::Holder compressed_holder;
      sensor_msgs_msg_dds__CompressedImage_ compressed{};
      if (internal::FillCompressedImage(image, compressed_format_, jpeg_quality_, compressed_holder,
                                        &compressed_bytes_, &compressed)) {
        compressed.header.stamp = internal::ShiftStamp(compressed.header.stamp, offset_);
        compressed_->Write(&compressed, internal::StampNs(compressed.header.stamp), stats_);
      } else if (!said_uncompressible_) {
        said_uncompressible_ = true;
        log::Log(log::Level::kWarn, "dds: {}: {} images have no {} form; none sent",
                 compressed_topic_name_, ToString(image.format()), compressed_format_);
      }
    }
  }
  int matched() const override { return image_->matched(); }
  const LinkStats& stats() const override { return stats_; }

 private:
  OutletFactory make_;  // holds the participant: destroyed after the outlets
  int64_t offset_;
  std::string compressed_format_;
  int jpeg_quality_;
  std::string compressed_topic_name_;
  std::unique_ptr<Outlet> image_, info_, tf_, compressed_;
  std::vector<uint8_t> compressed_bytes_;  // reused: the encoded image
  bool said_uncompressible_ = false;
  LinkStats stats_;
};

// head.joints, head.command, vision.target and mapping.map: one ROS message each (and a
// sibling: joint states' targets, the map's inhibited places).
template <typename M, typename Sample>
class SimpleWriter final : public Writer {
 public:
  SimpleWriter(OutletFactory make, const TopicOptions& options,
               const dds_topic_descriptor_t* descriptor)
      : Writer(MessageName<M>(), options.topic),
        make_(std::move(make)),
        lockstep_(options.lockstep),
        offset_(options.stamp_offset_ns) {
    writer_ = make_(descriptor, options.topic, options.qos, lockstep_);
    if constexpr (std::is_same_v<M, JointStateMessage>) {
      if (!options.targets_topic.empty()) {
        sibling_ = make_(descriptor, options.targets_topic, options.qos, false);
      }
      if (!options.robot_description_topic.empty()) {
        description_ = make_(&std_msgs_msg_dds__String__desc, options.robot_description_topic,
                             Qos::Latched(), false);
      }
      if (!options.tf_topic.empty()) {
        // ROS 2's tf QoS (reliable, keep last 100), transient local as the images' poses.
        tf_ = make_(&tf2_msgs_msg_dds__TFMessage__desc, options.tf_topic,
                    {Reliability::kReliable, Durability::kTransientLocal, 100}, false);
      }
    }
    if constexpr (std::is_same_v<M, MapMessage>) {
      if (!options.inhibited_topic.empty()) {
        sibling_ = make_(descriptor, options.inhibited_topic, options.qos, false);
      }
    }
  }
  void WriteErased(const void* message) override {
    const M& m = *static_cast<const M*>(message);
    if (!Publishable(m)) return;
    if constexpr (std::is_same_v<M, JointStateMessage>) {
      if (m.head) WriteRobot(m);
      // The targets first, so that a reader has them when the state arrives.
      if (sibling_) {
        head::JointState targets, velocities;
        internal::TargetsToSend(m, &targets, &velocities);
        internal::Holder holder;
        Sample sample{};
        internal::FillJointState(m.time, targets, &velocities, holder, &sample);
        sample.header.stamp = internal::ShiftStamp(sample.header.stamp, offset_);
        sibling_->Write(&sample, internal::StampNs(sample.header.stamp), stats_);
      }
    }
    if constexpr (std::is_same_v<M, MapMessage>) {
      // The inhibited places first, so that a reader has them when the map arrives.
      if (sibling_) {
        internal::Holder holder;
        Sample sample{};
        internal::FillInhibitedCloud(m, holder, &sample);
        sample.header.stamp = internal::ShiftStamp(sample.header.stamp, offset_);
        sibling_->Write(&sample, internal::StampNs(sample.header.stamp), stats_);
      }
    }
    internal::Holder holder;
    Sample sample{};
    Fill(m, holder, &sample);
    sample.header.stamp = internal::ShiftStamp(sample.header.stamp, offset_);
    writer_->Write(&sample, internal::StampNs(sample.header.stamp), stats_);
    ++stats_.messages;
    written_up_to_ = std::max(written_up_to_, m.time);
  }
  void MarkStep(double time) override {
    if (!lockstep_) Writer::MarkStep(time);
    if constexpr (std::is_same_v<Sample, sensor_msgs_msg_dds__JointState_>) {
      if (written_up_to_ < time - kStepMargin) {
        // No joint named: a step mark, not a command (JointsOf's readers skip it).
        internal::Holder holder;
        Sample mark{};
        internal::FillJointState(time, {}, nullptr, holder, &mark);
        mark.name = {0, 0, nullptr, false};
        mark.position = mark.velocity = {0, 0, nullptr, false};
        mark.header.stamp = internal::ShiftStamp(mark.header.stamp, offset_);
        writer_->Write(&mark, internal::StampNs(mark.header.stamp), stats_);
      }
    }
    written_up_to_ = -std::numeric_limits<double>::infinity();
  }
  int matched() const override { return writer_->matched(); }
  const LinkStats& stats() const override { return stats_; }

 private:
  // The head's URDF once (again if the head changes) and the pose of every link, before the
  // joint state, as robot_state_publisher does: rviz2 draws the robot from them.
  void WriteRobot(const JointStateMessage& m) {
    const int64_t stamp_ns =
        internal::StampNs(internal::ShiftStamp(internal::ToStamp(m.time), offset_));
    if (description_ && m.head != described_) {
      const std::string urdf = internal::RobotDescription(*m.head);
      std_msgs_msg_dds__String_ text{};
      text.data = const_cast<char*>(urdf.c_str());
      description_->Write(&text, stamp_ns, stats_);
      described_ = m.head;
    }
    if (!tf_) return;
    internal::Holder holder;
    std::vector<geometry_msgs_msg_dds__TransformStamped_> transforms;
    try {
      internal::FillLinkTransforms(m.time, *m.head, m.positions, holder, &transforms);
    } catch (const InvalidArgument& error) {
      if (!said_no_tf_) {
        log::Log(log::Level::kWarn, "dds: {}: no TF for the head's links: {}", topic(),
                 error.what());
      }
      said_no_tf_ = true;
      return;
    }
    for (auto& t : transforms) t.header.stamp = internal::ShiftStamp(t.header.stamp, offset_);
    tf2_msgs_msg_dds__TFMessage_ tf{};
    tf.transforms = {static_cast<uint32_t>(transforms.size()),
                     static_cast<uint32_t>(transforms.size()), transforms.data(), false};
    tf_->Write(&tf, stamp_ns, stats_);
  }

  // A target that is not valid (nothing to look at) is not a point: it is not published.
  static bool Publishable(const TargetMessage& m) { return m.valid && m.p_W.allFinite(); }
  static bool Publishable(const JointStateMessage&) { return true; }
  static bool Publishable(const JointCommand&) { return true; }
  static bool Publishable(const MapMessage&) { return true; }

  static void Fill(const JointStateMessage& m, internal::Holder& holder,
                   sensor_msgs_msg_dds__JointState_* out) {
    internal::FillJointState(m.time, m.positions, &m.velocities, holder, out);
  }
  static void Fill(const JointCommand& m, internal::Holder& holder,
                   sensor_msgs_msg_dds__JointState_* out) {
    internal::FillJointState(m.time, m.positions, &m.velocities, holder, out);
  }
  static void Fill(const TargetMessage& m, internal::Holder& holder,
                   geometry_msgs_msg_dds__PointStamped_* out) {
    holder.strings.reserve(2);
    holder.strings.emplace_back(internal::kWorldFrame);
    out->header = {internal::ToStamp(m.time), holder.strings.back().data()};
    out->point = {m.p_W.x(), m.p_W.y(), m.p_W.z()};
  }
  static void Fill(const MapMessage& m, internal::Holder& holder,
                   sensor_msgs_msg_dds__PointCloud2_* out) {
    internal::FillMapCloud(m, holder, out);
  }

  OutletFactory make_;  // holds the participant: destroyed after the outlets
  std::unique_ptr<Outlet> writer_;
  // Joint states: their targets (TopicOptions::targets_topic); maps: the inhibited places
  // (inhibited_topic).
  std::unique_ptr<Outlet> sibling_;
  // Joint states with a head: its URDF (TopicOptions::robot_description_topic) and its links'
  // poses (tf_topic).
  std::unique_ptr<Outlet> description_, tf_;
  std::shared_ptr<const head::HeadModel> described_;  // the head whose URDF was sent
  bool said_no_tf_ = false;
  bool lockstep_;
  int64_t offset_;
  // The latest stamp written since the last step mark (MarkStep).
  double written_up_to_ = -std::numeric_limits<double>::infinity();
  LinkStats stats_;
};

// ---- readers -------------------------------------------------------------------------------

class ImageReader final : public Reader {
 public:
  ImageReader(std::shared_ptr<Participant> participant, const TopicOptions& options)
      : Reader(MessageName<ImageMessage>(), options.topic),
        participant_(std::move(participant)),
        frame_period_s_(options.frame_period_s) {
    const std::string info_topic = SiblingTopic(options.topic, "camera_info");
    image_topic_ = MakeTopic(*participant_, &sensor_msgs_msg_dds__Image__desc, options.topic);
    image_ = MakeReader(*participant_, image_topic_, options.qos, options.topic);
    info_topic_ = MakeTopic(*participant_, &sensor_msgs_msg_dds__CameraInfo__desc, info_topic);
    info_ = MakeReader(*participant_, info_topic_, Qos::Latched(), info_topic);
    if (!options.tf_topic.empty()) {
      tf_topic_ = MakeTopic(*participant_, &tf2_msgs_msg_dds__TFMessage__desc, options.tf_topic);
      // The images' durability: a reader of their history gets the poses of it.
      tf_ = MakeReader(*participant_, tf_topic_,
                       {Reliability::kReliable, options.qos.durability, 100}, options.tf_topic);
    }
    wait_ = std::make_unique<DataWait>(image_);
  }

  ~ImageReader() override {
    for (const Received& r : pending_) ddsi_serdata_unref(r.sample);
  }

  // The newest image stamped at or before `up_to` (every image when it is infinite); later ones
  // are kept, serialized, for a later call. Only the image handed over is converted (a copy of
  // megabytes): those before it are counted lost, never converted (converting each, a reader
  // that fell behind spent its time copying images it then dropped, and fell further behind).
  // Samples are taken serialized and the pixels copied once, from the received bytes into the
  // image.
  std::shared_ptr<const void> TakeErased(double timeout_s, double up_to) override {
    stats_.lost += LostSince(image_);
    TakeImages();
    if (pending_.empty() && timeout_s > 0) {
      wait_->Wait(timeout_s);
      TakeImages();
      if (pending_.empty()) ++stats_.late;
    }
    const int64_t limit = std::isinf(up_to) ? std::numeric_limits<int64_t>::max()
                                            : static_cast<int64_t>(std::floor(up_to * 1e9));
    std::optional<Received> chosen;
    while (!pending_.empty() && pending_.front().stamp <= limit) {
      if (chosen) {
        ddsi_serdata_unref(chosen->sample);
        ++stats_.lost;
      }
      chosen = pending_.front();
      pending_.pop_front();
    }
    if (!chosen) return nullptr;
    std::string error;
    std::shared_ptr<Image> image;
    WithView(chosen->sample, &error, [&](const sensor_msgs_msg_dds__Image_& msg) {
      image = internal::ImageOf(msg, &error, &pool_);
    });
    ddsi_serdata_unref(chosen->sample);
    if (!image) {
      ++stats_.lost;
      log::Log(log::Level::kWarn, "dds: {}: image dropped: {}", topic(), error);
      return nullptr;
    }
    // The sender's simulated time: its stamp less the offset it announced (whole ns).
    image->metadata().time = static_cast<double>(chosen->stamp) * 1e-9;
    Complete(*image, chosen->stamp, chosen->raw_stamp);
    return std::make_shared<const ImageMessage>(ImageMessage{std::move(image)});
  }
  int matched() const override { return SubscriptionMatches(image_); }
  const LinkStats& stats() const override { return stats_; }

 private:
  // A valid sample taken, with its reference, and its stamp in ns: the sender's simulated
  // time (the writer's offset taken off) and as it was written (that of its pose on /tf).
  struct Received {
    ddsi_serdata* sample;
    int64_t stamp;
    int64_t raw_stamp;
  };
  // Images kept for a later step (TakeErased's up_to): a few frames of a sender running ahead.
  static constexpr std::size_t kMaxPendingImages = 16;

  // Calls `use` with the image message of serialized `sample`, read in place (its pointers
  // into the sample's bytes, valid during the call); false (and `error`) when it is unreadable.
  template <typename Use>
  static bool WithView(ddsi_serdata* sample, std::string* error, Use use) {
    ddsrt_iovec_t bytes{};
    ddsi_serdata* ref = ddsi_serdata_to_ser_ref(sample, 0, ddsi_serdata_size(sample), &bytes);
    sensor_msgs_msg_dds__Image_ msg{};
    const bool readable = internal::ImageViewOfCdr(static_cast<const uint8_t*>(bytes.iov_base),
                                                   bytes.iov_len, &msg, error);
    if (readable) use(msg);
    ddsi_serdata_to_ser_unref(ref, &bytes);
    return readable;
  }

  // Appends every valid image sample there is to pending_, in arrival order, with its stamp
  // (read in place); drops the unreadable ones (counted lost, logged).
  void TakeImages() {
    for (;;) {
      ddsi_serdata* samples[kMaxTake] = {nullptr};
      dds_sample_info_t infos[kMaxTake];
      const dds_return_t n = dds_takecdr(image_.get(), samples, kMaxTake, infos, DDS_ANY_STATE);
      if (n <= 0) break;
      for (dds_return_t i = 0; i < n; ++i) {
        if (!infos[i].valid_data) {
          ddsi_serdata_unref(samples[i]);
          continue;
        }
        std::string error;
        int64_t raw_stamp = 0;
        if (!WithView(samples[i], &error, [&](const sensor_msgs_msg_dds__Image_& msg) {
              raw_stamp = internal::StampNs(msg.header.stamp);
            })) {
          ++stats_.lost;
          log::Log(log::Level::kWarn, "dds: {}: image dropped: {}", topic(), error);
          ddsi_serdata_unref(samples[i]);
          continue;
        }
        const int64_t stamp =
            raw_stamp - announcements_.Get(image_, infos[i].publication_handle).stamp_offset_ns;
        // The sender restarted (its stamps went back): what it sent before is of no step now.
        if (!pending_.empty() && stamp < pending_.back().stamp) Drop(pending_.size());
        pending_.push_back({samples[i], stamp, raw_stamp});
        if (pending_.size() > kMaxPendingImages) Drop(1);
      }
      if (n < kMaxTake) break;
    }
  }
  // Drops the `count` oldest kept images, counted lost.
  void Drop(std::size_t count) {
    for (std::size_t i = 0; i < count && !pending_.empty(); ++i) {
      ddsi_serdata_unref(pending_.front().sample);
      pending_.pop_front();
      ++stats_.lost;
    }
  }

  // Camera model, pose and frame index of a received image (`stamp` in the sender's simulated
  // time, `raw_stamp` as written, as its pose's).
  void Complete(Image& image, int64_t sim_stamp, int64_t stamp) {
    ImageMetadata& meta = image.metadata();
    if (last_stamp_ && sim_stamp < *last_stamp_) {
      ++stats_.restarts;
      received_ = 0;
      poses_.clear();
    }
    last_stamp_ = sim_stamp;
    meta.frame_index = frame_period_s_ > 0
                           ? static_cast<int64_t>(std::llround(meta.time / frame_period_s_))
                           : received_;
    ++received_;
    ++stats_.messages;
    const std::string frame = internal::OpticalFrame(meta.camera);
    const auto Poll = [&] {
      TakeAll<sensor_msgs_msg_dds__CameraInfo_>(
          info_, [&](const sensor_msgs_msg_dds__CameraInfo_& info, const dds_sample_info_t&) {
            std::string error;
            if (auto model = internal::CameraModelOf(info, &error)) {
              models_[info.header.frame_id ? info.header.frame_id : ""] =
                  std::make_shared<const geometry::CameraModel>(*model);
            } else {
              log::Log(log::Level::kWarn, "dds: camera info of {} ignored: {}", topic(), error);
            }
          });
      if (tf_.get() > 0) {
        TakeAll<tf2_msgs_msg_dds__TFMessage_>(tf_, [&](const tf2_msgs_msg_dds__TFMessage_& tf,
                                                       const dds_sample_info_t&) {
          for (uint32_t i = 0; i < tf.transforms._length; ++i) {
            const auto& t = tf.transforms._buffer[i];
            if (!t.child_frame_id) continue;
            auto& history = poses_[t.child_frame_id];
            history.emplace_back(internal::StampNs(t.header.stamp), internal::PoseOf(t.transform));
            if (history.size() > 64) history.pop_front();
          }
        });
      }
    };
    const auto Found = [&]() -> bool {
      if (!models_.contains(frame)) return false;
      if (tf_.get() <= 0) return true;
      const auto it = poses_.find(frame);
      if (it == poses_.end()) return false;
      for (const auto& [s, pose] : it->second) {
        if (s == stamp) return true;
      }
      return false;
    };
    // The pose and info were written before the image; allow them a moment on other sockets.
    Poll();
    if (!Found())
      WaitUntil(0.05, [&] {
        Poll();
        return Found();
      });
    if (const auto m = models_.find(frame); m != models_.end()) {
      geometry::SetCameraModel(meta, m->second);
    } else {
      ++stats_.incomplete;
    }
    if (tf_.get() > 0) {
      const geometry::Pose* best = nullptr;
      if (const auto it = poses_.find(frame); it != poses_.end()) {
        for (const auto& [s, pose] : it->second) {
          if (s <= stamp) best = &pose;  // the newest at or before the image's time
        }
      }
      if (best) {
        geometry::SetCameraPose(meta, *best);
      } else {
        ++stats_.incomplete;
      }
    }
  }

  std::shared_ptr<Participant> participant_;
  double frame_period_s_;
  Announcements announcements_;  // the image writers' stamp offsets
  Entity image_topic_, info_topic_, tf_topic_;
  Entity image_, info_, tf_;
  std::unique_ptr<DataWait> wait_;
  internal::ImagePool pool_;
  std::map<std::string, std::shared_ptr<const geometry::CameraModel>> models_;
  std::map<std::string, std::deque<std::pair<int64_t, geometry::Pose>>> poses_;
  std::optional<int64_t> last_stamp_;
  int64_t received_ = 0;
  LinkStats stats_;
  std::deque<Received> pending_;
};

template <typename M, typename Sample>
class SimpleReader final : public Reader {
 public:
  SimpleReader(std::shared_ptr<Participant> participant, const TopicOptions& options,
               const dds_topic_descriptor_t* descriptor)
      : Reader(MessageName<M>(), options.topic),
        participant_(std::move(participant)),
        lockstep_(options.lockstep) {
    topic_ = MakeTopic(*participant_, descriptor, options.topic);
    reader_ = MakeReader(*participant_, topic_, options.qos, options.topic);
    // Joint states' targets and the map's inhibited places come on a sibling topic.
    std::string sibling;
    if constexpr (std::is_same_v<M, JointStateMessage>) sibling = options.targets_topic;
    if constexpr (std::is_same_v<M, MapMessage>) sibling = options.inhibited_topic;
    if (!sibling.empty()) {
      sibling_topic_ = MakeTopic(*participant_, descriptor, sibling);
      sibling_ = MakeReader(*participant_, sibling_topic_, options.qos, sibling);
    }
    wait_ = std::make_unique<DataWait>(reader_);
  }
  std::shared_ptr<const void> TakeErased(double timeout_s, double up_to) override {
    stats_.lost += LostSince(reader_);
    Drain();
    if (pending_.empty() && timeout_s > 0) {
      wait_->Wait(timeout_s);
      Drain();
      if (pending_.empty()) ++stats_.late;
    }
    reached_.clear();  // a lockstep step's marks are its own
    // The newest at or before `up_to`; those before it are lost, those after it kept.
    std::shared_ptr<M> newest;
    while (!pending_.empty() && pending_.front()->time <= up_to) {
      if (newest) ++stats_.lost;
      newest = std::move(pending_.front());
      pending_.pop_front();
    }
    if (!newest) return nullptr;
    if (last_time_ && newest->time < *last_time_) ++stats_.restarts;
    last_time_ = newest->time;
    ++stats_.messages;
    if constexpr (std::is_same_v<M, JointStateMessage> || std::is_same_v<M, MapMessage>) {
      Complete(*newest);
    }
    return newest;
  }
  bool WaitForStep(double time, double timeout_s) override {
    if (!lockstep_) return true;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    for (;;) {
      Drain();
      // Matched writers are looked at again every 50 ms: one that went away ends the wait.
      bool reached = true;
      for (const dds_instance_handle_t writer : LockstepWriters()) {
        const auto it = reached_.find(writer);
        reached = reached && it != reached_.end() && it->second >= time - kStepMargin;
      }
      if (reached) return true;
      const double left =
          std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
      if (left <= 0) {
        ++stats_.late;
        return false;
      }
      wait_->Wait(std::min(left, 0.05));
    }
  }
  int lockstep_writers() override { return static_cast<int>(LockstepWriters().size()); }
  int matched() const override { return SubscriptionMatches(reader_); }
  const LinkStats& stats() const override { return stats_; }

 private:
  // Every message that arrived, in order, after those kept from earlier calls (stamped after
  // their step's time); step marks (empty JointStates) only note their writer's stamp.
  void Drain() {
    if constexpr (std::is_same_v<M, JointStateMessage>) {
      // Before the states: each state's targets were written before it.
      if (sibling_.get() > 0) {
        TakeAll<Sample>(sibling_, [&](const Sample& sample, const dds_sample_info_t& info) {
          Target target;
          std::string error;
          if (!internal::JointsOf(sample, &target.positions, &target.velocities, &error)) {
            log::Log(log::Level::kWarn, "dds: {}: targets dropped: {}", topic(), error);
            return;
          }
          KeepSibling(targets_by_time_, SiblingTime(sample, info), std::move(target));
        });
      }
    }
    if constexpr (std::is_same_v<M, MapMessage>) {
      // Before the maps: each map's inhibited places were written before it.
      if (sibling_.get() > 0) {
        TakeAll<Sample>(sibling_, [&](const Sample& sample, const dds_sample_info_t& info) {
          std::vector<components::InhibitedPlace> places;
          std::string error;
          if (!internal::InhibitedOf(sample, &places, &error)) {
            log::Log(log::Level::kWarn, "dds: {}: inhibited places dropped: {}", topic(), error);
            return;
          }
          KeepSibling(inhibited_by_time_, SiblingTime(sample, info), std::move(places));
        });
      }
    }
    TakeAll<Sample>(reader_, [&](const Sample& sample, const dds_sample_info_t& info) {
      // The sender's simulated time: the stamp less the offset its writer announced.
      const double time =
          internal::FromStamp(sample.header.stamp,
                              announcements_.Get(reader_, info.publication_handle).stamp_offset_ns);
      if (lockstep_) {
        double& reached = reached_.try_emplace(info.publication_handle, -kInfinity).first->second;
        reached = std::max(reached, time);
      }
      if (IsStepMark(sample)) return;
      std::string error;
      auto message = std::make_shared<M>();
      if (!Convert(sample, message.get(), &error)) {
        ++stats_.lost;
        log::Log(log::Level::kWarn, "dds: {}: message dropped: {}", topic(), error);
        return;
      }
      message->time = time;
      // The sender restarted (its stamps went back): what it sent before is of no step now.
      if (!pending_.empty() && message->time < pending_.back()->time) {
        stats_.lost += static_cast<int64_t>(pending_.size());
        pending_.clear();
      }
      pending_.push_back(std::move(message));
      if (pending_.size() > kMaxPending) {
        pending_.pop_front();
        ++stats_.lost;
      }
    });
  }

  // A sibling sample's time: its stamp less the offset its writer announced.
  double SiblingTime(const Sample& sample, const dds_sample_info_t& info) {
    return internal::FromStamp(
        sample.header.stamp,
        sibling_announcements_.Get(sibling_, info.publication_handle).stamp_offset_ns);
  }
  // Keeps what a sibling topic brought for the message of stamp `time`.
  template <typename T>
  static void KeepSibling(std::map<double, T>& by_time, double time, T value) {
    // The sender restarted (its stamps went back): what it sent before is of no message now.
    if (!by_time.empty() && time < by_time.rbegin()->first) by_time.clear();
    by_time[time] = std::move(value);
    if (by_time.size() > kMaxPending) by_time.erase(by_time.begin());
  }

  // The matched writers that announce lockstep in their user data (asked once per writer).
  std::vector<dds_instance_handle_t> LockstepWriters() {
    dds_instance_handle_t handles[kMaxLockstepQuery];
    const dds_return_t n = dds_get_matched_publications(reader_.get(), handles, kMaxLockstepQuery);
    std::vector<dds_instance_handle_t> out;
    for (dds_return_t i = 0; i < std::min<dds_return_t>(n, kMaxLockstepQuery); ++i) {
      if (announcements_.Get(reader_, handles[i]).lockstep) out.push_back(handles[i]);
    }
    return out;
  }

  // The targets of the same stamp, and whether the head has arrived on them as the sender
  // said; without them (a sender that sends none, or they were lost) the state is taken as
  // at rest on its positions when every velocity is within sim.head's 1e-4, and counted
  // incomplete.
  void Complete(JointStateMessage& m) {
    const auto it = targets_by_time_.find(m.time);
    if (it == targets_by_time_.end()) {
      if (sibling_.get() > 0) ++stats_.incomplete;
      return;
    }
    m.targets = it->second.positions;
    m.target_velocities = it->second.velocities;
    m.arrived = internal::ArrivedOn(m.positions, m.velocities, m.targets, m.target_velocities);
    targets_by_time_.erase(targets_by_time_.begin(), std::next(it));
  }

  // The inhibited places of the map's stamp; a map without them (lost, or a sender without
  // them: a ROS 2 node's cloud) has none and is counted incomplete when they were expected.
  void Complete(MapMessage& m) {
    const auto it = inhibited_by_time_.find(m.time);
    if (it == inhibited_by_time_.end()) {
      if (sibling_.get() > 0) ++stats_.incomplete;
      return;
    }
    m.inhibited = it->second;
    inhibited_by_time_.erase(inhibited_by_time_.begin(), std::next(it));
  }

  // An empty JointState (no joint named) marks a lockstep writer's step (Writer::MarkStep).
  static bool IsStepMark(const sensor_msgs_msg_dds__JointState_& s) {
    return s.name._length == 0 && s.position._length == 0;
  }
  static bool IsStepMark(const geometry_msgs_msg_dds__PointStamped_&) { return false; }
  static bool IsStepMark(const sensor_msgs_msg_dds__PointCloud2_&) { return false; }

  static bool Convert(const sensor_msgs_msg_dds__JointState_& s, JointStateMessage* m,
                      std::string* error) {
    if (!internal::JointsOf(s, &m->positions, &m->velocities, error)) return false;
    m->time = internal::FromStamp(s.header.stamp);
    // JointState has no targets; until Complete finds them, at rest (every velocity within
    // sim.head's 1e-4 tolerance) the head is where it is heading.
    m->targets = m->positions;
    m->arrived = internal::ArrivedOn(m->positions, m->velocities, m->targets, {});
    return true;
  }
  static bool Convert(const sensor_msgs_msg_dds__JointState_& s, JointCommand* m,
                      std::string* error) {
    if (!internal::JointsOf(s, &m->positions, &m->velocities, error)) return false;
    m->time = internal::FromStamp(s.header.stamp);
    return true;
  }
  static bool Convert(const geometry_msgs_msg_dds__PointStamped_& s, TargetMessage* m,
                      std::string* error) {
    const std::string frame = s.header.frame_id ? s.header.frame_id : "";
    if (frame != internal::kWorldFrame) {
      *error = "point in frame '" + frame + "', expected 'world'";
      return false;
    }
    m->time = internal::FromStamp(s.header.stamp);
    m->valid = true;
    m->p_W = Eigen::Vector3d(s.point.x, s.point.y, s.point.z);
    m->source = "dds";
    return true;
  }
  static bool Convert(const sensor_msgs_msg_dds__PointCloud2_& s, MapMessage* m,
                      std::string* error) {
    return internal::MapOf(s, m, error);
  }

  // Messages stamped after the time they were asked for (TakeErased's up_to), kept for a later
  // step: at most a reader's deepest history.
  static constexpr std::size_t kMaxPending = kMaxQosDepth;
  std::deque<std::shared_ptr<M>> pending_;
  std::shared_ptr<Participant> participant_;
  bool lockstep_;
  // Lockstep: each writer's latest stamp since the last Take, and whether a matched writer
  // announced lockstep (by DDS instance handle).
  static constexpr dds_return_t kMaxLockstepQuery = 64;
  std::map<dds_instance_handle_t, double> reached_;
  // What the matched writers announce: lockstep, their stamps' offset.
  Announcements announcements_, sibling_announcements_;
  // Joint states: the targets received, by stamp (TopicOptions::targets_topic).
  struct Target {
    head::JointState positions, velocities;
  };
  std::map<double, Target> targets_by_time_;
  // Maps: the inhibited places received, by stamp (TopicOptions::inhibited_topic).
  std::map<double, std::vector<components::InhibitedPlace>> inhibited_by_time_;
  Entity topic_, reader_;
  Entity sibling_topic_, sibling_;  // targets_topic or inhibited_topic
  std::unique_ptr<DataWait> wait_;
  std::optional<double> last_time_;
  LinkStats stats_;
};

// rosgraph_msgs/Clock on /clock (ClockWriter).
class CycloneClockWriter final : public ClockWriter {
 public:
  CycloneClockWriter(std::shared_ptr<Participant> participant, const std::string& topic,
                     int64_t stamp_offset_ns)
      : participant_(std::move(participant)), topic_name_(topic), offset_(stamp_offset_ns) {
    topic_ = MakeTopic(*participant_, &rosgraph_msgs_msg_dds__Clock__desc, topic);
    // Reliable, volatile, keep last 1: rclcpp's ClockQoS (best effort, keep last 1) and
    // reliable subscribers both match; keep last 1 never blocks on a slow reader.
    writer_ = MakeWriter(*participant_, topic_, {Reliability::kReliable, Durability::kVolatile, 1},
                         topic, false, offset_);
  }
  void Publish(double time) override {
    rosgraph_msgs_msg_dds__Clock_ clock{};
    clock.clock = internal::ShiftStamp(internal::ToStamp(time), offset_);
    WriteSample(writer_, &clock, topic_name_, stats_);
  }
  int matched() const override { return PublicationMatches(writer_); }

 private:
  std::shared_ptr<Participant> participant_;
  std::string topic_name_;
  int64_t offset_;
  Entity topic_, writer_;
  LinkStats stats_;
};

void CheckOptions(const TopicOptions& options) {
  DdsTopicName(options.topic);  // throws for a name that is not fully qualified and valid
  std::string error;
  if (!options.qos.IsValid(&error)) {
    throw InvalidArgument("dds: QoS of " + options.topic + ": " + error);
  }
  if (!options.tf_topic.empty()) DdsTopicName(options.tf_topic);
  if (!options.inhibited_topic.empty()) DdsTopicName(options.inhibited_topic);
  if (options.compressed_format != "" && options.compressed_format != "jpeg" &&
      options.compressed_format != "png") {
    throw InvalidArgument("dds: compressed images of " + options.topic +
                          ": expected jpeg, png or none, got '" + options.compressed_format + "'");
  }
  if (options.jpeg_quality < 1 || options.jpeg_quality > 100) {
    throw InvalidArgument(fmt::format("dds: JPEG quality of {}: expected 1..100, got {}",
                                      options.topic, options.jpeg_quality));
  }
}

void CheckCreate(const std::shared_ptr<Participant>& participant, const TopicOptions& options) {
  if (!participant) throw InvalidArgument("dds: no participant");
  CheckOptions(options);
}

std::string SupportedList() {
  std::string text;
  for (const std::string& type : SupportedMessageTypes()) {
    text += (text.empty() ? "" : ", ") + type + " (" + RosTypeOf(type) + ")";
  }
  return text;
}

}  // namespace

std::vector<std::string> SupportedMessageTypes() {
  return {MessageName<ImageMessage>(), MessageName<JointStateMessage>(),
          MessageName<JointCommand>(), MessageName<TargetMessage>(), MessageName<MapMessage>()};
}

std::string RosTypeOf(const std::string& message_type) {
  if (message_type == MessageName<ImageMessage>()) return "sensor_msgs/msg/Image";
  if (message_type == MessageName<JointStateMessage>()) return "sensor_msgs/msg/JointState";
  if (message_type == MessageName<JointCommand>()) return "sensor_msgs/msg/JointState";
  if (message_type == MessageName<TargetMessage>()) return "geometry_msgs/msg/PointStamped";
  if (message_type == MessageName<MapMessage>()) return "sensor_msgs/msg/PointCloud2";
  throw InvalidArgument("dds: message type '" + message_type +
                        "' has no ROS 2 form; DDS topics carry " + SupportedList());
}

void Writer::CheckType(const char* name) const {
  if (message_type_ != name) {
    throw InvalidArgument(
        fmt::format("dds: the writer of {} sends {}, not {}", topic_, message_type_, name));
  }
}

void Reader::CheckType(const char* name) const {
  if (message_type_ != name) {
    throw InvalidArgument(
        fmt::format("dds: the reader of {} gives {}, not {}", topic_, message_type_, name));
  }
}

void Writer::MarkStep(double) {
  throw InvalidArgument("dds: " + topic_ + ": the writer is not in lockstep");
}

bool Reader::WaitForStep(double, double) { return true; }

bool Reader::WaitForLockstepWriter(double timeout_s) {
  return WaitUntil(timeout_s, [&] { return lockstep_writers() > 0; });
}

bool Writer::WaitForReaders(int count, double timeout_s) const {
  return WaitUntil(timeout_s, [&] { return matched() >= count; });
}

bool Reader::WaitForWriters(int count, double timeout_s) const {
  return WaitUntil(timeout_s, [&] { return matched() >= count; });
}

namespace {

std::unique_ptr<Writer> MakeTypedWriter(OutletFactory make, const std::string& message_type,
                                        const TopicOptions& options) {
  if (message_type == MessageName<ImageMessage>()) {
    return std::make_unique<ImageWriter>(std::move(make), options);
  }
  if (message_type == MessageName<JointStateMessage>()) {
    return std::make_unique<SimpleWriter<JointStateMessage, sensor_msgs_msg_dds__JointState_>>(
        std::move(make), options, &sensor_msgs_msg_dds__JointState__desc);
  }
  if (message_type == MessageName<JointCommand>()) {
    return std::make_unique<SimpleWriter<JointCommand, sensor_msgs_msg_dds__JointState_>>(
        std::move(make), options, &sensor_msgs_msg_dds__JointState__desc);
  }
  if (message_type == MessageName<MapMessage>()) {
    return std::make_unique<SimpleWriter<MapMessage, sensor_msgs_msg_dds__PointCloud2_>>(
        std::move(make), options, &sensor_msgs_msg_dds__PointCloud2__desc);
  }
  return std::make_unique<SimpleWriter<TargetMessage, geometry_msgs_msg_dds__PointStamped_>>(
      std::move(make), options, &geometry_msgs_msg_dds__PointStamped__desc);
}

}  // namespace

std::unique_ptr<Writer> Writer::Create(std::shared_ptr<Participant> participant,
                                       const std::string& message_type,
                                       const TopicOptions& options) {
  RosTypeOf(message_type);  // throws for an unsupported type
  CheckCreate(participant, options);
  return MakeTypedWriter(DdsOutlets(std::move(participant), options.stamp_offset_ns), message_type,
                         options);
}

std::unique_ptr<Writer> Writer::CreateSerializing(const std::string& message_type,
                                                  const TopicOptions& options,
                                                  SerializedSink sink) {
  RosTypeOf(message_type);  // throws for an unsupported type
  if (!sink) throw InvalidArgument("dds: no sink for the serialized messages of " + options.topic);
  TopicOptions serializing = options;
  serializing.lockstep = false;
  CheckOptions(serializing);
  return MakeTypedWriter(SerializingOutlets(std::move(sink)), message_type, serializing);
}

namespace {

// The ROS 2 types saccade's IDL declares, by their ROS 2 names.
const std::vector<const dds_topic_descriptor_t*>& Descriptors() {
  static const std::vector<const dds_topic_descriptor_t*> descriptors = {
      &sensor_msgs_msg_dds__Image__desc,           &sensor_msgs_msg_dds__CameraInfo__desc,
      &sensor_msgs_msg_dds__CompressedImage__desc, &sensor_msgs_msg_dds__JointState__desc,
      &sensor_msgs_msg_dds__PointCloud2__desc,     &geometry_msgs_msg_dds__PointStamped__desc,
      &tf2_msgs_msg_dds__TFMessage__desc,          &std_msgs_msg_dds__String__desc,
      &rosgraph_msgs_msg_dds__Clock__desc};
  return descriptors;
}

class CycloneCdrWriter final : public CdrWriter {
 public:
  CycloneCdrWriter(std::shared_ptr<Participant> participant,
                   const dds_topic_descriptor_t* descriptor, const std::string& topic,
                   const Qos& qos)
      : participant_(std::move(participant)),
        descriptor_(descriptor),
        topic_name_(topic),
        ros_type_(internal::RosTypeName(descriptor->m_typename)),
        topic_(MakeTopic(*participant_, descriptor, topic)),
        writer_(MakeWriter(*participant_, topic_, qos, topic)),
        sample_(descriptor->m_size) {}

  void Write(const uint8_t* data, std::size_t size) override {
    std::fill(sample_.begin(), sample_.end(), 0);
    std::string error;
    if (!internal::DeserializeCdr(*descriptor_, data, size, sample_.data(), &error)) {
      throw InvalidArgument(fmt::format("dds: {} ({}): {}", topic_name_, ros_type_, error));
    }
    WriteSample(writer_, sample_.data(), topic_name_, stats_);
    dds_stream_free_sample(sample_.data(), descriptor_->m_ops);
  }
  int matched() const override { return PublicationMatches(writer_); }

 private:
  std::shared_ptr<Participant> participant_;
  const dds_topic_descriptor_t* descriptor_;
  std::string topic_name_;
  std::string ros_type_;
  Entity topic_, writer_;
  std::vector<char> sample_;  // the message read (operator new's alignment suits every type)
  LinkStats stats_;
};

}  // namespace

std::vector<std::string> RosMessageTypes() {
  std::vector<std::string> types;
  for (const dds_topic_descriptor_t* d : Descriptors()) {
    types.push_back(internal::RosTypeName(d->m_typename));
  }
  return types;
}

std::unique_ptr<CdrWriter> CdrWriter::Create(std::shared_ptr<Participant> participant,
                                             const std::string& ros_type, const std::string& topic,
                                             const Qos& qos) {
  if (!participant) throw InvalidArgument("dds: no participant");
  DdsTopicName(topic);  // throws for a name that is not fully qualified and valid
  std::string error;
  if (!qos.IsValid(&error)) throw InvalidArgument("dds: QoS of " + topic + ": " + error);
  for (const dds_topic_descriptor_t* d : Descriptors()) {
    if (internal::RosTypeName(d->m_typename) == ros_type) {
      return std::make_unique<CycloneCdrWriter>(std::move(participant), d, topic, qos);
    }
  }
  std::string known;
  for (const std::string& type : RosMessageTypes()) known += (known.empty() ? "" : ", ") + type;
  throw InvalidArgument("dds: " + topic + ": no ROS 2 type '" + ros_type + "' (saccade has " +
                        known + ")");
}

std::unique_ptr<ClockWriter> ClockWriter::Create(std::shared_ptr<Participant> participant,
                                                 const std::string& topic,
                                                 int64_t stamp_offset_ns) {
  if (!participant) throw InvalidArgument("dds: no participant");
  DdsTopicName(topic);  // throws for a name that is not fully qualified and valid
  return std::make_unique<CycloneClockWriter>(std::move(participant), topic, stamp_offset_ns);
}

std::unique_ptr<Reader> Reader::Create(std::shared_ptr<Participant> participant,
                                       const std::string& message_type,
                                       const TopicOptions& options) {
  RosTypeOf(message_type);
  CheckCreate(participant, options);
  if (message_type == MessageName<ImageMessage>()) {
    return std::make_unique<ImageReader>(std::move(participant), options);
  }
  if (message_type == MessageName<JointStateMessage>()) {
    return std::make_unique<SimpleReader<JointStateMessage, sensor_msgs_msg_dds__JointState_>>(
        std::move(participant), options, &sensor_msgs_msg_dds__JointState__desc);
  }
  if (message_type == MessageName<JointCommand>()) {
    return std::make_unique<SimpleReader<JointCommand, sensor_msgs_msg_dds__JointState_>>(
        std::move(participant), options, &sensor_msgs_msg_dds__JointState__desc);
  }
  if (message_type == MessageName<MapMessage>()) {
    return std::make_unique<SimpleReader<MapMessage, sensor_msgs_msg_dds__PointCloud2_>>(
        std::move(participant), options, &sensor_msgs_msg_dds__PointCloud2__desc);
  }
  return std::make_unique<SimpleReader<TargetMessage, geometry_msgs_msg_dds__PointStamped_>>(
      std::move(participant), options, &geometry_msgs_msg_dds__PointStamped__desc);
}

}  // namespace saccade::dds
