#include "saccade/record/recorder.h"

#include <fmt/format.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "record/pipeline/internal_channels.h"
#include "saccade/components/messages.h"
#include "saccade/components/roles.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"
#include "saccade/dds/topic_names.h"
#include "saccade/dds/topics.h"
#include "saccade/record/mcap.h"
#include "saccade/render/dataset.h"

namespace saccade::record {

namespace {

// Steps handed over and not yet written, at most: the loop waits beyond (bounded memory).
constexpr std::size_t kMaxQueuedSteps = 2;

}  // namespace

struct PipelineRecorder::Impl {
  // One tapped output: serialized to ROS 2 messages by `ros`, or written as JSON on `json`.
  struct Source {
    std::unique_ptr<dds::Writer> ros;
    std::string json_topic;
    bool camera_image = false;  // an eye camera's image (not its mosaic): in the step's frame
  };
  // A message sent during the step, kept until the writing thread takes it.
  struct Pending {
    Source* source = nullptr;
    std::shared_ptr<const void> message;  // ROS: the message
    std::string json;                     // JSON: its text
    uint64_t publish_time = 0;            // JSON: its time
  };
  struct Step {
    uint64_t log_time = 0;
    std::vector<Pending> messages;
  };

  std::filesystem::path path;
  RecorderOptions options;
  McapWriter writer;
  std::vector<std::unique_ptr<Source>> sources;
  std::vector<std::pair<runtime::OutputBase*, runtime::ConnectionId>> connections;
  std::map<std::string, std::unique_ptr<Source>> extra;  // AddJson's, by topic
  std::string frames_topic;  // each step's frame record, as render --record's (/saccade/frames)

  std::mutex step_mutex;  // guards `step` (outputs emit from any thread)
  std::vector<Pending> step;

  // The writing thread's side.
  std::mutex queue_mutex;
  std::condition_variable queue_changed;
  std::deque<Step> queue;
  bool closing = false;
  bool closed = false;
  std::exception_ptr failure;
  int64_t steps = 0;
  uint64_t messages = 0;
  uint64_t bytes = 0;
  std::thread thread;

  // Written by the writing thread only.
  uint64_t log_time = 0;
  internal::Channels channels{writer};

  Impl(const std::filesystem::path& p, RecorderOptions o)
      : path(p), options(std::move(o)), writer(p, internal::WriterOptions(options)) {}

  void Tap(runtime::Pipeline& pipeline);
  // Keeps each message of `output` (one of dds::SupportedMessageTypes) for `source`.
  runtime::ConnectionId ConnectRos(runtime::OutputBase& output, Source* source);
  template <runtime::Message M>
  std::optional<runtime::ConnectionId> ConnectAs(runtime::OutputBase& output, Source* source) {
    auto* typed = dynamic_cast<runtime::Output<M>*>(&output);
    if (typed == nullptr) return std::nullopt;
    return typed->signal().Connect(
        [this, source](const M& m) { Add(source, std::make_shared<M>(m)); });
  }
  void Add(Source* source, std::shared_ptr<const void> message) {
    std::lock_guard lock(step_mutex);
    step.push_back({source, std::move(message), {}, 0});
  }
  void AddJsonText(Source* source, const nlohmann::json& json, uint64_t publish_time) {
    Pending p{source, nullptr, json.dump(), publish_time};
    std::lock_guard lock(step_mutex);
    step.push_back(std::move(p));
  }
  // The step's frame record (render/dataset.h's FrameRecord, without files or truth) from the
  // metadata of its camera images, written after them by the writing thread: what
  // sensor_msgs/Image cannot say, the motion-blur sub-frames and the camera controls
  // (exposure, gain, focus) of each image.
  void WriteFrameRecord(const Step& s);
  void WriteLoop();
  void WriteStep(Step& s);
  void RethrowFailure() {
    std::lock_guard lock(queue_mutex);
    if (failure) std::rethrow_exception(failure);
  }
};

void PipelineRecorder::Impl::Tap(runtime::Pipeline& pipeline) {
  const std::string image_type = runtime::MessageName<runtime::ImageMessage>();
  const std::string joints_type = runtime::MessageName<components::JointStateMessage>();
  const auto ros_types = dds::SupportedMessageTypes();
  for (const auto& component : pipeline.components()) {
    const auto* cameras = dynamic_cast<const components::EyeCamerasRole*>(component.get());
    const bool head = dynamic_cast<components::HeadRole*>(component.get()) != nullptr;
    for (const auto& output : component->outputs()) {
      const std::string& type = output->message_type();
      auto source = std::make_unique<Source>();
      Source* raw = source.get();
      runtime::ConnectionId id = 0;
      std::string topic;
      try {
        topic = dds::ResolveTopic(component->name() + "/" + output->name(), options.ns);
      } catch (const InvalidArgument& error) {
        log::Log(log::Level::kWarn, "record: {}.{} is not recorded: {}", component->name(),
                 output->name(), error.what());
        continue;
      }
      if (std::find(ros_types.begin(), ros_types.end(), type) != ros_types.end()) {
        dds::TopicOptions t;
        t.topic = topic;
        t.tf_topic = "";
        t.compressed_format = "";
        const std::string mosaic = cameras != nullptr && type == image_type
                                       ? cameras->RawMosaicCamera(output->name())
                                       : "";
        if (!mosaic.empty()) {
          // A camera's raw mosaic beside its image, as render --record's depth and ids: its
          // pose is the image's, on /tf once.
          t.topic = dds::ResolveTopic(mosaic + "/raw/image_raw", options.ns);
        } else if (cameras != nullptr && type == image_type) {
          t.topic = dds::ResolveTopic(output->name() + "/image_raw", options.ns);
          t.tf_topic = "/tf";
          raw->camera_image = true;
        } else if (head && type == joints_type && output->name() == "joints") {
          t.topic = dds::ResolveTopic("joint_states", options.ns);
          t.targets_topic = dds::ResolveTopic("joint_targets", options.ns);
          t.robot_description_topic = dds::ResolveTopic("robot_description", options.ns);
          t.tf_topic = "/tf";
        } else if (type == runtime::MessageName<components::MapMessage>()) {
          t.inhibited_topic = topic + "/inhibited";  // as the pipeline's transport sends it
        }
        raw->ros = dds::Writer::CreateSerializing(
            type, t, [this](const dds::SerializedMessage& m) { channels.Write(m, log_time); });
        // Typed: images are kept by their shared pixels, not converted during the step.
        id = ConnectRos(*output, raw);
      } else {
        raw->json_topic = topic;
        id = output->ConnectJson([this, raw](const nlohmann::json& json) {
          const auto time = json.is_object() ? json.find("time") : json.end();
          const double t = time != json.end() && time->is_number() ? time->get<double>() : -1.0;
          AddJsonText(raw, json, internal::Nanoseconds(t));
        });
      }
      connections.emplace_back(output.get(), id);
      sources.push_back(std::move(source));
    }
  }
}

runtime::ConnectionId PipelineRecorder::Impl::ConnectRos(runtime::OutputBase& output,
                                                         Source* source) {
  std::optional<runtime::ConnectionId> id = ConnectAs<runtime::ImageMessage>(output, source);
  if (!id) id = ConnectAs<components::JointStateMessage>(output, source);
  if (!id) id = ConnectAs<components::JointCommand>(output, source);
  if (!id) id = ConnectAs<components::TargetMessage>(output, source);
  if (!id) id = ConnectAs<components::MapMessage>(output, source);
  SACCADE_ASSERT(id.has_value(),
                 "record: a ROS 2 type the recorder cannot keep: " + output.message_type());
  return *id;
}

void PipelineRecorder::Impl::WriteFrameRecord(const Step& s) {
  std::vector<render::Frame> images;
  for (const Pending& p : s.messages) {
    if (!p.source->camera_image) continue;
    const auto& m = *static_cast<const runtime::ImageMessage*>(p.message.get());
    if (m.image) images.push_back(render::Frame{m.image, nullptr, nullptr, {}, nullptr});
  }
  if (images.empty()) return;
  const ImageMetadata& first = images.front().color->metadata();
  const std::string record =
      render::FrameRecord(first.frame_index, first.time, images, {}, false, false).dump();
  writer.Write(channels.Of(frames_topic, ""), log_time, internal::Nanoseconds(first.time),
               {reinterpret_cast<const uint8_t*>(record.data()), record.size()});
}

void PipelineRecorder::Impl::WriteStep(Step& s) {
  log_time = s.log_time;
  for (Pending& p : s.messages) {
    if (p.source->ros) {
      p.source->ros->WriteErased(p.message.get());
    } else {
      const auto* data = reinterpret_cast<const uint8_t*>(p.json.data());
      writer.Write(channels.Of(p.source->json_topic, ""), log_time,
                   p.publish_time == 0 ? log_time : p.publish_time, {data, p.json.size()});
    }
  }
  WriteFrameRecord(s);
}

void PipelineRecorder::Impl::WriteLoop() {
  for (;;) {
    Step s;
    {
      std::unique_lock lock(queue_mutex);
      queue_changed.wait(lock, [&] { return closing || !queue.empty(); });
      if (queue.empty()) return;
      s = std::move(queue.front());
    }
    try {
      WriteStep(s);
    } catch (...) {
      std::lock_guard lock(queue_mutex);
      if (!failure) failure = std::current_exception();
    }
    std::lock_guard lock(queue_mutex);
    queue.pop_front();
    ++steps;
    messages = writer.statistics().message_count;
    bytes = writer.bytes_written();
    queue_changed.notify_all();
  }
}

PipelineRecorder::PipelineRecorder(runtime::Pipeline& pipeline, const std::filesystem::path& path,
                                   RecorderOptions options)
    : impl_(std::make_unique<Impl>(path, std::move(options))) {
  impl_->writer.AddMetadata("saccade", impl_->options.metadata);
  impl_->frames_topic = dds::ResolveTopic("frames", impl_->options.ns);
  impl_->Tap(pipeline);
  impl_->thread = std::thread([this] {
    pthread_setname_np(pthread_self(), "mcap-writer");  // in top and perf
    // Below the loop's threads: the writing uses the cores' idle moments (a loop waiting on
    // the renderer's readback), and the queue bounds how far it may fall behind. SCHED_IDLE
    // (any user may ask it for its own threads) runs it only on an idle core; niced where
    // the kernel refuses.
    const sched_param idle{};
    if (pthread_setschedparam(pthread_self(), SCHED_IDLE, &idle) != 0) {
      setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
    }
    impl_->WriteLoop();
  });
}

PipelineRecorder::~PipelineRecorder() {
  for (const auto& [output, id] : impl_->connections) output->Disconnect(id);
  {
    std::lock_guard lock(impl_->queue_mutex);
    impl_->closing = true;
  }
  impl_->queue_changed.notify_all();
  if (impl_->thread.joinable()) impl_->thread.join();
  // The McapWriter, destroyed without Close, leaves the file as a recording cut short.
}

void PipelineRecorder::AfterStep(const runtime::StepContext& context) {
  impl_->RethrowFailure();
  Impl::Step s;
  s.log_time = internal::Nanoseconds(context.time);
  {
    std::lock_guard lock(impl_->step_mutex);
    s.messages.swap(impl_->step);
  }
  std::unique_lock lock(impl_->queue_mutex);
  impl_->queue_changed.wait(lock, [&] { return impl_->queue.size() < kMaxQueuedSteps; });
  impl_->queue.push_back(std::move(s));
  impl_->queue_changed.notify_all();
}

void PipelineRecorder::AddJson(const std::string& topic, double time,
                               const nlohmann::json& message) {
  auto& source = impl_->extra[topic];
  if (!source) {
    source = std::make_unique<Impl::Source>();
    source->json_topic = topic;
  }
  impl_->AddJsonText(source.get(), message, internal::Nanoseconds(time));
}

RecordingStats PipelineRecorder::Close() {
  Impl& r = *impl_;
  if (!r.closed) {
    {
      std::lock_guard lock(r.queue_mutex);
      r.closing = true;
    }
    r.queue_changed.notify_all();
    if (r.thread.joinable()) r.thread.join();
    r.RethrowFailure();
    r.closed = true;
    r.writer.Close();
    r.messages = r.writer.statistics().message_count;
    r.bytes = r.writer.bytes_written();
  }
  return stats();
}

RecordingStats PipelineRecorder::stats() const {
  std::lock_guard lock(impl_->queue_mutex);
  return {impl_->steps, impl_->messages, impl_->bytes};
}

const std::filesystem::path& PipelineRecorder::path() const { return impl_->path; }

}  // namespace saccade::record
