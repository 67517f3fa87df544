#pragma once
// Conversions between saccade's messages and the ROS 2 types idlc generates (Cyclone's C
// structs). The writers' side fills structs that borrow the message's memory (pixels and
// strings are not copied: the struct is only valid while the message and `Holder` live); the
// readers' side copies out of Cyclone's loaned samples.
#include <dds/ddsi/ddsi_cdrstream.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "dds/internal_cyclone.h"
#include "saccade/components/messages.h"
#include "saccade/core/image.h"
#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/pose.h"

namespace saccade::dds::internal {

/// Seconds to builtin_interfaces/Time (nanosec in [0, 1e9), rounded to the nanosecond).
builtin_interfaces_msg_dds__Time_ ToStamp(double seconds);
double FromStamp(const builtin_interfaces_msg_dds__Time_& stamp);
/// The stamp in nanoseconds, exact (for matching an image with its pose).
int64_t StampNs(const builtin_interfaces_msg_dds__Time_& stamp);

/// `stamp` moved by `offset_ns` (TopicOptions::stamp_offset_ns), exactly.
builtin_interfaces_msg_dds__Time_ ShiftStamp(const builtin_interfaces_msg_dds__Time_& stamp,
                                             int64_t offset_ns);
/// The simulated time of a stamp written with `offset_ns` (stamp - offset, whole ns, then
/// seconds: the same double as FromStamp of the unshifted stamp).
inline double FromStamp(const builtin_interfaces_msg_dds__Time_& stamp, int64_t offset_ns) {
  return static_cast<double>(StampNs(stamp) - offset_ns) * 1e-9;
}

/// The world frame's name, and a camera's optical frame ("left" -> "left_optical").
inline constexpr const char* kWorldFrame = "world";
std::string OpticalFrame(const std::string& camera);
/// The camera of an optical frame ("left_optical" -> "left"; other names as they are).
std::string CameraOfFrame(const std::string& frame);

/// sensor_msgs/Image encodings of saccade's pixel formats ("rgb8", "mono8", "bayer_rggb8", ...);
/// nullopt for a format ROS has no encoding for.
std::optional<std::string> RosEncoding(PixelFormat format);
std::optional<PixelFormat> FormatOfEncoding(const std::string& encoding);

/// Memory a filled struct borrows (strings that are not the message's own).
struct Holder {
  std::vector<std::string> strings;
  std::vector<char*> string_pointers;
  std::vector<double> doubles[3];
  std::vector<sensor_msgs_msg_dds__PointField_> fields;  // a point cloud's
  std::vector<uint8_t> bytes;                            // a point cloud's points
};

/// `image` as sensor_msgs/Image, borrowing its pixels and `holder`'s strings. False when its
/// format has no ROS encoding.
bool FillImage(const Image& image, Holder& holder, sensor_msgs_msg_dds__Image_* out);
/// The image's camera model as sensor_msgs/CameraInfo; false when it carries none.
bool FillCameraInfo(const Image& image, Holder& holder, sensor_msgs_msg_dds__CameraInfo_* out);
/// The image's pose X_WC as a transform world -> the camera's optical frame; false when none.
bool FillCameraTransform(const Image& image, Holder& holder,
                         geometry_msgs_msg_dds__TransformStamped_* out);

/// `image` encoded as sensor_msgs/CompressedImage: `format` "jpeg" (quality 1..100) or
/// "png", `*bytes` holds the encoded data and `out` borrows it. The format string is
/// image_transport's compressed plugin's ("rgb8; jpeg compressed bgr8"). False for pixels it
/// has no form for (JPEG: rgb8, rgba8, mono8; PNG: those and mono16).
bool FillCompressedImage(const Image& image, const std::string& format, int jpeg_quality,
                         Holder& holder, std::vector<uint8_t>* bytes,
                         sensor_msgs_msg_dds__CompressedImage_* out);

/// The camera model of a CameraInfo; nullopt (and `*error` says why) when it is not one
/// (zero K, unknown distortion model, wrong coefficient count).
std::optional<geometry::CameraModel> CameraModelOf(const sensor_msgs_msg_dds__CameraInfo_& info,
                                                   std::string* error);
/// The transform's pose (rotation from the normalised quaternion).
geometry::Pose PoseOf(const geometry_msgs_msg_dds__Transform_& transform);
/// sensor_msgs/Image read in place from its serialized form (`size` bytes: the 4-byte
/// encapsulation header, then XCDR1, little- or big-endian): `*out`'s strings and pixels point
/// into `cdr`, valid while it lives. False (and `*error` says what and at which byte) when the
/// bytes are not one whole Image. The reader takes images this way, not as Cyclone's samples:
/// those are a copy of the pixels of their own, and the image's copy out of them a second.
bool ImageViewOfCdr(const uint8_t* cdr, std::size_t size, sensor_msgs_msg_dds__Image_* out,
                    std::string* error);

/// Serializes samples as Cyclone writes them for rmw_cyclonedds: the 4-byte encapsulation header
/// (CDR, this machine's byte order: little-endian), then XCDR1. Keeps its buffer from message to
/// message (an image's megabytes are neither allocated nor copied again). One thread at a time.
class CdrSerializer {
 public:
  CdrSerializer();
  ~CdrSerializer();
  CdrSerializer(const CdrSerializer&) = delete;
  CdrSerializer& operator=(const CdrSerializer&) = delete;
  /// `sample` (of `descriptor`'s type) serialized; valid until the next call.
  std::span<const uint8_t> Serialize(const dds_topic_descriptor_t& descriptor, const void* sample);

 private:
  dds_ostream_t os_;
};

/// Reads serialized bytes (`size`: the 4-byte encapsulation header, then XCDR1 of either byte
/// order) into `sample`, zero-filled and of `descriptor`'s type; its strings and sequences are
/// allocated by Cyclone (free them with dds_stream_free_sample). False (and `*error` says
/// why) when the bytes are not one whole message of the type.
bool DeserializeCdr(const dds_topic_descriptor_t& descriptor, const uint8_t* data, std::size_t size,
                    void* sample, std::string* error);

/// The ROS 2 name of an idlc type name: "sensor_msgs::msg::dds_::Image_" ->
/// "sensor_msgs/msg/Image".
std::string RosTypeName(const std::string& dds_type_name);

/// Images a reader handed out before, reused once nobody else holds them. A received frame is
/// megabytes: a fresh one costs a page fault per 4 KiB page, and between frames the heap gave
/// the pages back to the kernel (on the dev VM 15 ms of CPU for a 1024x768 RGB frame, against
/// 0.3 ms into pages already mapped). One thread uses a pool.
class ImagePool {
 public:
  explicit ImagePool(std::size_t capacity = 4) : capacity_(capacity) {}
  /// An image of that size and format that only the pool holds (metadata cleared, pixels
  /// left as they were), or a new one, kept when there is room.
  std::shared_ptr<Image> Get(int width, int height, PixelFormat format);

 private:
  std::size_t capacity_;
  std::size_t next_ = 0;  // the entry replaced when every one is held elsewhere
  std::vector<std::shared_ptr<Image>> images_;
};

/// An image from sensor_msgs/Image (pixels copied, rows re-packed when step is wider), from
/// `pool` when given; nullptr (and `*error` says why) for an unknown encoding, big-endian data
/// or a short buffer.
std::shared_ptr<Image> ImageOf(const sensor_msgs_msg_dds__Image_& msg, std::string* error,
                               ImagePool* pool = nullptr);

/// sensor_msgs/PointField's datatype FLOAT32 (its constant; the others are not used here).
inline constexpr uint8_t kPointFieldFloat32 = 7;

/// The map's occupied voxels as sensor_msgs/PointCloud2: frame "world", stamped with its time,
/// height 1, width N, little-endian FLOAT32 fields x, y, z (metres, offsets 0, 4, 8) and rgb
/// (offset 12: PCL's packed 0x00RRGGBB, coloured by height over the map's own z range with
/// HeightColor), point_step 16, is_dense. The data lives in `holder`.
void FillMapCloud(const components::MapMessage& map, Holder& holder,
                  sensor_msgs_msg_dds__PointCloud2_* out);
/// The places inhibition of return holds as sensor_msgs/PointCloud2 (the map's sibling topic):
/// as FillMapCloud, fields x, y, z, strength (0..1], radius (m), point_step 20.
void FillInhibitedCloud(const components::MapMessage& map, Holder& holder,
                        sensor_msgs_msg_dds__PointCloud2_* out);
/// A colour for height `t` in [0, 1] (clamped): blue, cyan, green, yellow, red, as 0x00RRGGBB.
uint32_t HeightColor(double t);

/// Reads the named fields of every point of `cloud` (FLOAT32 or FLOAT64, count 1, anywhere in
/// the point), point by point into `*values` (N x names.size()). False (and `*error` says which
/// field or size is wrong) for a big-endian cloud, a missing or mistyped field, or data
/// shorter than its rows.
bool CloudFields(const sensor_msgs_msg_dds__PointCloud2_& cloud,
                 const std::vector<std::string>& names, std::vector<double>* values,
                 std::string* error);
/// The occupied voxels' centres of a PointCloud2 in frame "world" (fields x, y, z); time from its
/// stamp. False (and `*error` says why) for another frame or what CloudFields refuses. The
/// cloud does not carry resolution_m, frame_index or fused: they stay 0.
bool MapOf(const sensor_msgs_msg_dds__PointCloud2_& cloud, components::MapMessage* map,
           std::string* error);
/// The inhibited places of a cloud FillInhibitedCloud wrote (fields x, y, z, strength, radius).
bool InhibitedOf(const sensor_msgs_msg_dds__PointCloud2_& cloud,
                 std::vector<components::InhibitedPlace>* places, std::string* error);

/// Every link of `head` at `positions` (by name) as TF, as robot_state_publisher sends them:
/// world -> the root link (the head's pose X_WB), then for each joint its parent link -> child
/// link; frame ids are the URDF's link names. `out`'s strings point into `holder`. Throws
/// InvalidArgument (HeadModel::Posture) when `positions` are not the head's joints.
void FillLinkTransforms(double time, const head::HeadModel& head, const head::JointState& positions,
                        Holder& holder, std::vector<geometry_msgs_msg_dds__TransformStamped_>* out);
/// The head's URDF for robot_description: its own file's text, or for a head without one
/// (legacy POPEYE) the URDF `saccade urdf` writes (head::ExportUrdf).
std::string RobotDescription(const head::HeadModel& head);

/// A head's joints as a sensor_msgs/JointState, with their names (POPEYE: pan, tilt, left,
/// right); `velocities` may be null. The names point into the states' shared name lists.
void FillJointState(double time, const head::JointState& positions,
                    const head::JointState* velocities, Holder& holder,
                    sensor_msgs_msg_dds__JointState_* out);
/// Positions and velocities of a JointState, with the message's names in its order (the
/// receiver arranges them in its head's order by name); false (and `*error` says why) when the
/// lengths disagree, a name is empty or named twice. Velocities are zero when it has none.
bool JointsOf(const sensor_msgs_msg_dds__JointState_& msg, head::JointState* positions,
              head::JointState* velocities, std::string* error);

/// Whether a head with these positions and velocities has arrived on these targets: every
/// joint within sim.head's 1e-4 (rad, rad/s) of its target in position and velocity.
bool ArrivedOn(const head::JointState& positions, const head::JointState& velocities,
               const head::JointState& targets, const head::JointState& target_velocities);
/// The targets to send with a joint state (TopicOptions::targets_topic) so that the receiver's
/// ArrivedOn gives the sender's `arrived`: its targets and their velocities, except for a head
/// that has arrived by a tolerance of its own, wider than ArrivedOn's (servos settle within a
/// tick): then where it is. (A head that says it has not arrived while within 1e-4 of its
/// targets reads as arrived.)
void TargetsToSend(const components::JointStateMessage& m, head::JointState* targets,
                   head::JointState* target_velocities);

}  // namespace saccade::dds::internal
