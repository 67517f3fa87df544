#include "saccade/record/frame_recorder.h"

#include <map>
#include <memory>

#include "record/pipeline/internal_channels.h"
#include "saccade/components/messages.h"
#include "saccade/core/error.h"
#include "saccade/dds/topic_names.h"
#include "saccade/dds/topics.h"
#include "saccade/record/mcap.h"
#include "saccade/runtime/message.h"

namespace saccade::record {

struct FrameRecorder::Impl {
  const scene::Scene& scene;
  render::TruthRequest truth;
  RecorderOptions options;
  McapWriter writer;
  internal::Channels channels{writer};
  uint64_t log_time = 0;
  // Per camera: its image, depth and id writers (made on the camera's first frame).
  struct Camera {
    std::unique_ptr<dds::Writer> image, raw, depth, ids;
  };
  std::map<std::string, Camera> cameras;
  std::unique_ptr<dds::Writer> joints;
  std::shared_ptr<const head::HeadModel> head;
  int64_t frames = 0;
  bool closed = false;

  Impl(const scene::Scene& s, const render::TruthRequest& t, const std::filesystem::path& path,
       RecorderOptions o)
      : scene(s), truth(t), options(std::move(o)), writer(path, internal::WriterOptions(options)) {}

  std::unique_ptr<dds::Writer> ImageWriter(const std::string& topic, const std::string& tf) {
    dds::TopicOptions t;
    t.topic = dds::ResolveTopic(topic, options.ns);
    t.tf_topic = tf;
    t.compressed_format = "";
    return dds::Writer::CreateSerializing(
        runtime::MessageName<runtime::ImageMessage>(), t,
        [this](const dds::SerializedMessage& m) { channels.Write(m, log_time); });
  }
  Camera& CameraOf(const std::string& name) {
    Camera& c = cameras[name];
    if (!c.image) {
      c.image = ImageWriter(name + "/image_raw", "/tf");
      if (truth.depth) c.depth = ImageWriter(name + "/depth/image_raw", "");
      if (truth.ids) c.ids = ImageWriter(name + "/ids/image_raw", "");
    }
    return c;
  }
};

FrameRecorder::FrameRecorder(const scene::Scene& scene, const render::TruthRequest& truth,
                             const std::filesystem::path& path, RecorderOptions options)
    : impl_(std::make_unique<Impl>(scene, truth, path, std::move(options))) {
  Impl& r = *impl_;
  r.writer.AddMetadata("saccade", r.options.metadata);
  if (scene.robot()) {
    r.head = std::make_shared<head::HeadModel>(scene.robot()->head);
    dds::TopicOptions t;
    t.topic = dds::ResolveTopic("joint_states", r.options.ns);
    t.targets_topic = dds::ResolveTopic("joint_targets", r.options.ns);
    t.robot_description_topic = dds::ResolveTopic("robot_description", r.options.ns);
    t.tf_topic = "/tf";
    r.joints = dds::Writer::CreateSerializing(
        runtime::MessageName<components::JointStateMessage>(), t,
        [&r](const dds::SerializedMessage& m) { r.channels.Write(m, r.log_time); });
  }
}

FrameRecorder::~FrameRecorder() = default;

void FrameRecorder::Write(int64_t index, double time, const scene::SceneState& state,
                          const std::vector<render::Frame>& frames) {
  Impl& r = *impl_;
  if (r.closed) throw InvalidArgument("record: a frame after Close");
  r.log_time = internal::Nanoseconds(time);
  if (r.joints && state.joints.size() > 0) {
    components::JointStateMessage joints;
    joints.time = time;
    joints.positions = state.joints;
    joints.targets = state.joints;
    joints.velocities = state.joint_velocities.size() == state.joints.size()
                            ? state.joint_velocities
                            : state.joints.With(Eigen::VectorXd::Zero(state.joints.size()));
    joints.target_velocities = joints.velocities;
    joints.head = r.head;
    r.joints->Write(joints);
  }
  for (const render::Frame& frame : frames) {
    if (!frame.color) continue;
    Impl::Camera& camera = r.CameraOf(frame.color->metadata().camera);
    camera.image->Write(runtime::ImageMessage{frame.color});
    if (frame.raw) {
      // The raw mosaic of a camera with a colour filter (bayer_rggb8, ...), beside its image.
      if (!camera.raw) {
        camera.raw = r.ImageWriter(frame.color->metadata().camera + "/raw/image_raw", "");
      }
      camera.raw->Write(runtime::ImageMessage{frame.raw});
    }
    if (camera.depth && frame.depth) camera.depth->Write(runtime::ImageMessage{frame.depth});
    if (camera.ids && frame.ids) {
      auto ids =
          std::make_shared<Image>(render::IdsToPng16(*frame.ids, frame.color->metadata().camera));
      ids->metadata() = frame.ids->metadata();
      camera.ids->Write(runtime::ImageMessage{std::move(ids)});
    }
  }
  const std::string record =
      render::FrameRecord(index, time, frames, r.truth, !r.scene.objects().empty(), false).dump();
  r.writer.Write(r.channels.Of(dds::ResolveTopic("frames", r.options.ns), ""), r.log_time,
                 r.log_time, {reinterpret_cast<const uint8_t*>(record.data()), record.size()});
  ++r.frames;
}

RecordingStats FrameRecorder::Close() {
  Impl& r = *impl_;
  if (!r.closed) {
    r.writer.Close();
    r.closed = true;
  }
  return {r.frames, r.writer.statistics().message_count, r.writer.bytes_written()};
}

}  // namespace saccade::record
