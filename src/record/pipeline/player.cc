#include "saccade/record/player.h"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "saccade/components/messages.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"
#include "saccade/dds/participant.h"
#include "saccade/dds/qos.h"
#include "saccade/dds/topic_names.h"
#include "saccade/dds/topics.h"
#include "saccade/dds/transport.h"
#include "saccade/record/mcap.h"

namespace saccade::record {

namespace {

// The QoS the robot's writers use for each type (dds/topics.h): transient local throughout, so
// that a reader that matches a moment late still gets the step's messages.
dds::Qos QosOf(const std::string& ros_type) {
  using dds::Durability;
  using dds::Reliability;
  if (ros_type == "sensor_msgs/msg/Image" || ros_type == "sensor_msgs/msg/CompressedImage") {
    return {Reliability::kReliable, Durability::kTransientLocal, 2};
  }
  if (ros_type == "tf2_msgs/msg/TFMessage") {
    return {Reliability::kReliable, Durability::kTransientLocal, 100};
  }
  return dds::Qos::Latched();
}

}  // namespace

struct McapPlayer::Impl {
  std::filesystem::path file;
  PlayOptions options;
  McapReader reader;
  std::shared_ptr<dds::Participant> participant;
  std::map<uint16_t, std::unique_ptr<dds::CdrWriter>> writers;  // by channel
  std::set<uint16_t> images;                                    // channels of images
  std::unique_ptr<dds::Reader> answers;                         // lockstep
  std::vector<std::string> skipped;
  double last_time = 0.0;

  std::atomic<bool> stop{false};
  std::thread thread;
  mutable std::mutex mutex;  // guards stats and failure
  PlayStats stats;
  std::exception_ptr failure;

  Impl(const std::filesystem::path& f, PlayOptions o) : file(f), options(std::move(o)), reader(f) {}

  void Play();
  // After the messages of one step: its pacing.
  void EndStep(uint64_t log_time, double stamp, bool first,
               std::chrono::steady_clock::time_point start, uint64_t first_log_time);
};

void McapPlayer::Impl::EndStep(uint64_t log_time, double stamp, bool first,
                               std::chrono::steady_clock::time_point start,
                               uint64_t first_log_time) {
  {
    std::lock_guard lock(mutex);
    ++stats.steps;
  }
  if (options.pace == "recorded") {
    const double at = static_cast<double>(log_time - first_log_time) * 1e-9 / options.speed;
    std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                              std::chrono::duration<double>(at)));
  } else if (options.pace == "lockstep") {
    if (first && !answers->WaitForLockstepWriter(options.start_wait_s)) {
      log::Log(log::Level::kWarn,
               "play: no pipeline answers in lockstep on {} after {} s; playing on without "
               "waiting for one (until one comes)",
               answers->topic(), options.start_wait_s);
    }
    if (!answers->WaitForStep(stamp, options.step_wait_s)) {
      std::lock_guard lock(mutex);
      if (++stats.late == 1) {
        log::Log(log::Level::kWarn,
                 "play: no answer in lockstep for the step at {:.3f} s within {} s; playing on "
                 "(the late ones are counted)",
                 stamp, options.step_wait_s);
      }
    }
    answers->TakeErased(0.0, std::numeric_limits<double>::infinity());
  }
}

void McapPlayer::Impl::Play() {
  const auto start = std::chrono::steady_clock::now();
  bool have_step = false, first = true;
  uint64_t step_time = 0, first_log_time = 0;
  double step_stamp = 0.0;
  reader.ForEachMessage([&](const McapMessage& m) {
    if (stop) return false;
    if (!have_step || m.log_time != step_time) {
      if (have_step) {
        EndStep(step_time, step_stamp, first, start, first_log_time);
        first = false;
      } else {
        first_log_time = m.log_time;
      }
      have_step = true;
      step_time = m.log_time;
      step_stamp = static_cast<double>(m.log_time) * 1e-9;
    }
    const auto writer = writers.find(m.channel_id);
    if (writer == writers.end()) return true;
    if (images.count(m.channel_id)) step_stamp = static_cast<double>(m.publish_time) * 1e-9;
    writer->second->Write(m.data.data(), m.data.size());
    std::lock_guard lock(mutex);
    ++stats.messages;
    return true;
  });
  if (have_step && !stop) EndStep(step_time, step_stamp, first, start, first_log_time);
  std::lock_guard lock(mutex);
  stats.finished = !stop;
}

McapPlayer::McapPlayer(const std::filesystem::path& file, const nlohmann::json& transport,
                       PlayOptions options)
    : impl_(std::make_unique<Impl>(file, std::move(options))) {
  Impl& p = *impl_;
  if (p.options.pace != "lockstep" && p.options.pace != "recorded" && p.options.pace != "fast") {
    throw InvalidArgument("play: pace must be lockstep, recorded or fast, got '" + p.options.pace +
                          "'");
  }
  if (!(p.options.speed > 0.0) || !std::isfinite(p.options.speed)) {
    throw InvalidArgument(fmt::format("play: speed must be > 0, got {}", p.options.speed));
  }
  std::string ns;
  const dds::DomainOptions domain = dds::ParseTransport(transport, &ns);
  p.participant = dds::Participant::Create(domain);
  const auto known = dds::RosMessageTypes();
  for (const auto& [id, channel] : p.reader.channels()) {
    const auto schema = p.reader.schemas().find(channel.schema_id);
    const std::string type = schema == p.reader.schemas().end() ? "" : schema->second.name;
    if (channel.message_encoding != "cdr") {
      p.skipped.push_back(channel.topic + " (" + channel.message_encoding + ")");
    } else if (std::find(known.begin(), known.end(), type) == known.end()) {
      p.skipped.push_back(channel.topic + " (" + type + ": no ROS 2 form in saccade)");
    } else {
      p.writers[id] = dds::CdrWriter::Create(p.participant, type, channel.topic, QosOf(type));
      if (type == "sensor_msgs/msg/Image") p.images.insert(id);
    }
  }
  if (p.writers.empty()) {
    throw InvalidArgument("play: " + file.string() +
                          " holds no ROS 2 message saccade can publish (no cdr channel of "
                          "sensor_msgs, geometry_msgs, tf2_msgs or std_msgs types)");
  }
  if (p.reader.statistics().message_count == 0) {
    throw InvalidArgument("play: " + file.string() + " holds no message");
  }
  p.last_time = static_cast<double>(p.reader.statistics().message_end_time) * 1e-9;
  if (p.options.pace == "lockstep") {
    dds::TopicOptions t;
    t.topic = dds::ResolveTopic(p.options.command_topic, ns);
    t.lockstep = true;
    p.answers =
        dds::Reader::Create(p.participant, runtime::MessageName<components::JointCommand>(), t);
  }
}

McapPlayer::~McapPlayer() {
  try {
    Stop();
  } catch (const std::exception& e) {
    log::Log(log::Level::kWarn, "play: {}", e.what());
  }
}

void McapPlayer::Start() {
  Impl& p = *impl_;
  if (p.thread.joinable()) return;
  p.thread = std::thread([&p] {
    try {
      p.Play();
    } catch (...) {
      std::lock_guard lock(p.mutex);
      p.failure = std::current_exception();
    }
  });
}

PlayStats McapPlayer::Stop() {
  Impl& p = *impl_;
  p.stop = true;
  if (p.thread.joinable()) p.thread.join();
  std::lock_guard lock(p.mutex);
  if (p.failure) std::rethrow_exception(std::exchange(p.failure, nullptr));
  return p.stats;
}

PlayStats McapPlayer::stats() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->stats;
}

double McapPlayer::last_time() const { return impl_->last_time; }
const std::vector<std::string>& McapPlayer::skipped() const { return impl_->skipped; }

}  // namespace saccade::record
