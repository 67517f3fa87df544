#include "saccade/dds/transport.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <type_traits>

#include "saccade/components/messages.h"
#include "saccade/core/log.h"
#include "saccade/dds/topic_names.h"
#include "saccade/dds/topics.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::dds {
namespace {

using components::JointCommand;
using components::JointStateMessage;
using components::MapMessage;
using components::TargetMessage;
using runtime::ImageMessage;
using runtime::MessageName;

void CheckKeys(const nlohmann::json& map, const std::set<std::string>& known,
               const std::string& where) {
  for (const auto& [key, value] : map.items()) {
    if (!known.contains(key)) {
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      throw InvalidArgument(fmt::format("{}: unknown key '{}'; expected {}", where, key, list));
    }
  }
}

double Seconds(const nlohmann::json& map, const char* key, const std::string& where) {
  const auto it = map.find(key);
  if (it == map.end()) return 0.0;
  if (!it->is_number() || it->get<double>() < 0 || it->get<double>() > 3600) {
    throw InvalidArgument(
        fmt::format("{}.{}: expected seconds 0..3600, got {}", where, key, it->dump()));
  }
  return it->get<double>();
}

// `lockstep: true` (TopicOptions::lockstep): head commands only; on the real-time clock the
// wall clock paces the steps, so it is off there.
bool Lockstep(const runtime::TopicEndpoint& endpoint) {
  const auto it = endpoint.options.find("lockstep");
  if (it == endpoint.options.end()) return false;
  if (!it->is_boolean()) {
    throw InvalidArgument(
        fmt::format("{}.lockstep: expected true or false, got {}", endpoint.where, it->dump()));
  }
  if (it->get<bool>() && endpoint.message_type != MessageName<JointCommand>()) {
    throw InvalidArgument(
        fmt::format("{}.lockstep: only head commands ({}) mark steps; this port carries {}",
                    endpoint.where, MessageName<JointCommand>(), endpoint.message_type));
  }
  return it->get<bool>() && endpoint.pipeline != nullptr &&
         endpoint.pipeline->clock.mode == runtime::ClockMode::kSimulated;
}

// One participant per domain and configuration in the process: Cyclone allows few per host.
std::shared_ptr<Participant> SharedParticipant(const DomainOptions& options) {
  static std::mutex mutex;
  static std::map<std::string, std::weak_ptr<Participant>> participants;
  std::lock_guard lock(mutex);
  std::string key = fmt::format("{}|{}|{}|{}", options.domain_id, options.config, options.interface,
                                options.multicast);
  for (const std::string& peer : options.peers) key += "|" + peer;
  if (auto existing = participants[key].lock()) return existing;
  auto participant = Participant::Create(options);
  participants[key] = participant;
  return participant;
}

// The pipeline steps on the sender's stamps (runtime's clock.source).
bool OnStamps(const runtime::TopicEndpoint& endpoint) {
  return endpoint.pipeline != nullptr && !endpoint.pipeline->clock.source.empty() &&
         endpoint.pipeline->clock.mode == runtime::ClockMode::kSimulated;
}
// History of a reader in such a pipeline: 2.5 s of a 25 Hz sender running ahead; images,
// 2.25 MiB each at 1024x768, 16 (the image reader keeps as many).
constexpr int kOnStampsDepth = 64;
constexpr int kOnStampsImageDepth = 16;
// How long a lockstep reader's step waits for its answer when the file does not say (wait_s).
constexpr double kLockstepWaitS = 10.0;
// Where joint states' targets go by default: /saccade/joint_states -> /saccade/joint_targets.
constexpr char kTargetsSibling[] = "joint_targets";
// Where a joint-state writer puts its head's URDF: robot_description in the namespace (a
// robot_state_publisher in that namespace publishes it there too).
constexpr char kRobotDescription[] = "robot_description";

struct Endpoint {
  std::shared_ptr<Participant> participant;
  TopicOptions options;
};

Endpoint Resolve(const runtime::TopicEndpoint& endpoint, const std::set<std::string>& keys) {
  const std::string where = endpoint.where;
  CheckKeys(endpoint.options, keys, where);
  std::string ns;
  TransportNames names;
  const nlohmann::json transport =
      endpoint.pipeline ? endpoint.pipeline->transport : nlohmann::json::object();
  const DomainOptions domain = ParseTransport(transport, &ns, &names);
  Endpoint out;
  out.options.stamp_offset_ns = names.wall_stamps ? WallStampOffsetNs() : 0;
  out.options.topic = ResolveTopic(endpoint.topic, ns);
  RosTypeOf(endpoint.message_type);  // names the supported types when this one is not
  out.options.qos = DefaultQos(endpoint.message_type);
  if (const auto it = endpoint.options.find("qos"); it != endpoint.options.end()) {
    out.options.qos = ParseQos(*it, where + ".qos");
  }
  if (const auto it = endpoint.options.find("tf"); it != endpoint.options.end()) {
    if (!it->is_string()) throw InvalidArgument(where + ".tf: expected a topic or \"\"");
    const std::string tf = it->get<std::string>();
    out.options.tf_topic = tf.empty() ? "" : ResolveTopic(tf, ns);
  }
  // Joint states carry their targets on a sibling topic (TopicOptions::targets_topic).
  const bool joints = endpoint.message_type == MessageName<JointStateMessage>();
  if (joints) out.options.targets_topic = SiblingTopic(out.options.topic, kTargetsSibling);
  // Maps carry the places inhibition of return holds on `<topic>/inhibited`.
  if (endpoint.message_type == MessageName<MapMessage>()) {
    out.options.inhibited_topic = out.options.topic + "/inhibited";
  }
  // And the head's URDF on robot_description (TopicOptions::robot_description_topic).
  if (joints) out.options.robot_description_topic = ResolveTopic(kRobotDescription, ns);
  if (const auto it = endpoint.options.find(kRobotDescription); it != endpoint.options.end()) {
    if (!joints || !it->is_string()) {
      throw InvalidArgument(
          fmt::format("{}.robot_description: expected a topic or \"\" (joint states only), got {}",
                      where, it->dump()));
    }
    const std::string topic = it->get<std::string>();
    out.options.robot_description_topic = topic.empty() ? "" : ResolveTopic(topic, ns);
  }
  if (const auto it = endpoint.options.find("targets"); it != endpoint.options.end()) {
    if (!joints) {
      throw InvalidArgument(
          fmt::format("{}.targets: only joint states have targets; this port carries {}", where,
                      endpoint.message_type));
    }
    if (!it->is_string()) throw InvalidArgument(where + ".targets: expected a topic or \"\"");
    const std::string targets = it->get<std::string>();
    out.options.targets_topic = targets.empty() ? "" : ResolveTopic(targets, ns);
  }
  const bool image = endpoint.message_type == MessageName<ImageMessage>();
  if (const auto it = endpoint.options.find("compressed"); it != endpoint.options.end()) {
    if (!image) {
      throw InvalidArgument(
          fmt::format("{}.compressed: only images are compressed; this port "
                      "carries {}",
                      where, endpoint.message_type));
    }
    if (!it->is_string() || (*it != "jpeg" && *it != "png" && *it != "")) {
      throw InvalidArgument(fmt::format("{}.compressed: expected jpeg, png or \"\" (none), got {}",
                                        where, it->dump()));
    }
    out.options.compressed_format = it->get<std::string>();
  }
  if (const auto it = endpoint.options.find("jpeg_quality"); it != endpoint.options.end()) {
    if (!image || !it->is_number_integer() || it->get<int64_t>() < 1 || it->get<int64_t>() > 100) {
      throw InvalidArgument(
          fmt::format("{}.jpeg_quality: expected an integer 1..100 (images), "
                      "got {}",
                      where, it->dump()));
    }
    out.options.jpeg_quality = it->get<int>();
  }
  if (endpoint.pipeline && endpoint.pipeline->clock.mode == runtime::ClockMode::kSimulated) {
    out.options.frame_period_s = endpoint.pipeline->clock.step;
  }
  if (OnStamps(endpoint)) {
    // Deep enough to hold the message of the step's time while the sender runs ahead.
    out.options.qos.depth =
        std::max(out.options.qos.depth, image ? kOnStampsImageDepth : kOnStampsDepth);
  }
  out.options.lockstep = Lockstep(endpoint);
  out.participant = SharedParticipant(domain);
  return out;
}

// A received message's capture time (its header.stamp), seconds.
double StampOf(const ImageMessage& m) { return m.image ? m.image->metadata().time : 0.0; }
template <typename M>
double StampOf(const M& m) {
  return m.time;
}

// Emits what the topic received each step. As the pipeline's time source (clock.source) it
// takes the step's message before the step, in NextTime, and emits that one in Step.
template <runtime::Message M>
class TopicReaderComponent final : public runtime::Component, public runtime::TimeSource {
 public:
  // `on_stamps`: the pipeline steps on the sender's stamps (clock.source); each step takes
  // the newest message stamped at or before its time.
  // `lockstep`: each step waits for the writers in lockstep (TopicOptions::lockstep).
  TopicReaderComponent(std::unique_ptr<Reader> reader, double wait_s, double start_wait_s,
                       bool on_stamps, bool lockstep)
      : reader_(std::move(reader)),
        wait_s_(wait_s),
        start_wait_s_(start_wait_s),
        on_stamps_(on_stamps),
        lockstep_(lockstep),
        output_(AddOutput<M>("message")) {}

  std::optional<double> NextTime() override {
    StartWait();
    taken_ = true;
    // With no sender the steps have nothing to time them: each waits its wait_s for one to
    // come (picked up at once when it does) rather than spinning through empty steps.
    if (wait_s_ > 0 && reader_->matched() == 0) {
      if (!waiting_for_writer_) {
        log::Info("dds: {}: no writer; each step waits up to {} s for one", reader_->topic(),
                  wait_s_);
      }
      waiting_for_writer_ = !reader_->WaitForWriters(1, wait_s_);
    }
    pending_ = Take(std::numeric_limits<double>::infinity());
    if (!pending_) return std::nullopt;
    return StampOf(*pending_);
  }
  void Step(const runtime::StepContext& context) override {
    // The step's time is its message's stamp (whole nanoseconds) or that put on the step grid
    // (SimulatedStepTime): a microsecond's margin, far below a sender's step, covers both.
    const double up_to = on_stamps_ ? context.time + 1e-6 : std::numeric_limits<double>::infinity();
    std::shared_ptr<const M> message;
    StartWait();
    if (taken_) {
      message = std::move(pending_);
    } else if (lockstep_) {
      // The step's answer from every writer in lockstep (a command or a step mark), then the
      // newest command that came, without a second wait.
      if (!reader_->WaitForStep(context.time, wait_s_) && ++late_steps_ == 1) {
        log::Log(log::Level::kWarn,
                 "dds: {}: no answer in lockstep for the step at {:.3f} s within {} s; stepping "
                 "on (the late ones are counted)",
                 reader_->topic(), context.time, wait_s_);
      }
      message = reader_->Take<M>(0.0, up_to);
    } else {
      message = Take(up_to);
    }
    taken_ = false;
    pending_.reset();
    if (message) output_.Emit(*message);
  }
  void Stop() override {
    const LinkStats& s = reader_->stats();
    log::Info("dds: {} ({}): {} messages, {} lost, {} late, {} restarts{}", reader_->topic(),
              RosTypeOf(reader_->message_type()), s.messages, s.lost, s.late, s.restarts,
              s.incomplete
                  ? fmt::format(", {} without {}", s.incomplete,
                                std::is_same_v<M, ImageMessage> ? "camera info or pose" : "targets")
                  : "");
  }

 private:
  // The first step's wait for the peer (start_wait_s), where its message is needed rather than
  // in Start: the components before this reader have stepped, and published, already. In
  // lockstep the step waits for a writer in lockstep, so that it is in lockstep already.
  void StartWait() {
    if (start_waited_) return;
    start_waited_ = true;
    if (start_wait_s_ <= 0) return;
    if (lockstep_) {
      if (!reader_->WaitForLockstepWriter(start_wait_s_)) {
        log::Log(log::Level::kWarn,
                 "dds: {}: no writer in lockstep after {} s; stepping on without waiting for one "
                 "(until one comes)",
                 reader_->topic(), start_wait_s_);
      }
    } else if (!reader_->WaitForWriters(1, start_wait_s_)) {
      log::Log(log::Level::kWarn, "dds: {}: no writer after {} s; stepping on without one",
               reader_->topic(), start_wait_s_);
    }
  }

  // Waits only while a writer is there: a sender that went away never blocks the loop.
  std::shared_ptr<const M> Take(double up_to) {
    const double wait = wait_s_ > 0 && reader_->matched() > 0 ? wait_s_ : 0.0;
    return reader_->Take<M>(wait, up_to);
  }

  std::unique_ptr<Reader> reader_;
  double wait_s_;
  double start_wait_s_;
  bool on_stamps_;
  bool lockstep_;
  int64_t late_steps_ = 0;
  runtime::Output<M>& output_;
  bool start_waited_ = false;        // StartWait ran (the first step)
  bool taken_ = false;               // NextTime took this step's message
  bool waiting_for_writer_ = false;  // NextTime found no writer (said once)
  std::shared_ptr<const M> pending_;
};

// A lockstep writer also marks each step done (Writer::MarkStep), returned for the pipeline's
// EndStep; an empty function otherwise.
template <runtime::Message M>
std::function<void(const runtime::StepContext&)> AttachWriter(std::shared_ptr<Writer> writer,
                                                              double start_wait_s, bool lockstep,
                                                              runtime::OutputBase& port) {
  auto* typed = dynamic_cast<runtime::Output<M>*>(&port);
  SACCADE_ASSERT(typed != nullptr, "output of the wrong type");
  // The first message goes out at once, as every other topic's; the wait for a reader
  // (start_wait_s) comes at the end of its step, against a deadline from that message, so that
  // the pipeline's writers wait together, never one topic's first message for another's reader.
  struct StartWait {
    std::optional<std::chrono::steady_clock::time_point> deadline;
    bool done = false;
  };
  auto start = std::make_shared<StartWait>();
  typed->signal().Connect([writer, start_wait_s, start](const M& message) {
    if (!start->deadline) {
      start->deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(start_wait_s));
    }
    writer->Write(message);
  });
  if (!lockstep && start_wait_s <= 0) return {};
  return [writer, start_wait_s, lockstep, start](const runtime::StepContext& context) {
    if (lockstep) writer->MarkStep(context.time);
    if (start_wait_s > 0 && start->deadline && !start->done) {
      start->done = true;
      const double left =
          std::chrono::duration<double>(*start->deadline - std::chrono::steady_clock::now())
              .count();
      if (writer->matched() == 0 && !writer->WaitForReaders(1, std::max(0.0, left))) {
        log::Log(log::Level::kWarn, "dds: {}: no reader after {} s; writing without one",
                 writer->topic(), start_wait_s);
      }
    }
  };
}

template <typename F>
auto Dispatch(const std::string& type, F&& f) {
  if (type == MessageName<ImageMessage>()) return f(ImageMessage{});
  if (type == MessageName<JointStateMessage>()) return f(JointStateMessage{});
  if (type == MessageName<JointCommand>()) return f(JointCommand{});
  if (type == MessageName<TargetMessage>()) return f(TargetMessage{});
  if (type == MessageName<MapMessage>()) return f(MapMessage{});
  RosTypeOf(type);  // throws, naming the supported types
  SACCADE_ASSERT(false, "unreachable");
}

}  // namespace

int64_t WallStampOffsetNs() {
  static const int64_t offset = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                    std::chrono::system_clock::now().time_since_epoch())
                                    .count();
  return offset;
}

DomainOptions ParseTransport(const nlohmann::json& transport, std::string* ns,
                             TransportNames* names) {
  const std::string where = "transport";
  if (!transport.is_object()) throw InvalidArgument("transport: expected a map");
  CheckKeys(transport,
            {"domain", "namespace", "config", "interface", "peers", "multicast", "stamps", "clock"},
            where);
  DomainOptions options;
  if (const auto it = transport.find("domain"); it != transport.end()) {
    if (!it->is_number_integer() || it->get<int64_t>() < 0 || it->get<int64_t>() > kMaxDomainId) {
      throw InvalidArgument(fmt::format("transport.domain: expected an integer 0..{}, got {}",
                                        kMaxDomainId, it->dump()));
    }
    options.domain_id = it->get<int>();
  }
  const auto String = [&](const char* key, std::string* out) {
    if (const auto it = transport.find(key); it != transport.end()) {
      if (!it->is_string()) {
        throw InvalidArgument(
            fmt::format("transport.{}: expected a string, got {}", key, it->dump()));
      }
      *out = it->get<std::string>();
    }
  };
  std::string name_space;
  String("namespace", &name_space);
  String("config", &options.config);
  String("interface", &options.interface);
  if (const auto it = transport.find("peers"); it != transport.end()) {
    if (!it->is_array()) throw InvalidArgument("transport.peers: expected a list of hosts");
    for (const auto& peer : *it) {
      if (!peer.is_string()) throw InvalidArgument("transport.peers: expected host names");
      options.peers.push_back(peer.get<std::string>());
    }
  }
  if (const auto it = transport.find("multicast"); it != transport.end()) {
    if (!it->is_boolean()) throw InvalidArgument("transport.multicast: expected true or false");
    options.multicast = it->get<bool>();
  }
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument("transport: " + error);
  if (!name_space.empty()) ResolveTopic("x", name_space);  // checks the namespace
  if (ns) *ns = name_space;
  TransportNames out;
  out.ns = name_space;
  if (const auto it = transport.find("stamps"); it != transport.end()) {
    if (!it->is_string() || (*it != "sim" && *it != "wall")) {
      throw InvalidArgument(fmt::format(
          "transport.stamps: expected sim (simulated seconds from 0) or wall (the wall clock at "
          "the start plus those), got {}",
          it->dump()));
    }
    out.wall_stamps = *it == "wall";
  }
  if (const auto it = transport.find("clock"); it != transport.end()) {
    if (!it->is_string()) {
      throw InvalidArgument(
          fmt::format("transport.clock: expected a topic or \"\" (none), got {}", it->dump()));
    }
    out.clock_topic = it->get<std::string>();
  }
  if (!out.clock_topic.empty()) {
    try {
      out.clock_topic = ResolveTopic(out.clock_topic, name_space);
    } catch (const Error& error) {
      throw InvalidArgument(std::string("transport.clock: ") + error.what());
    }
  }
  if (names) *names = out;
  return options;
}

Qos DefaultQos(const std::string& message_type) {
  if (message_type == MessageName<ImageMessage>()) return Qos::Images();
  if (message_type == MessageName<JointStateMessage>()) return Qos::Latched();
  // A viewer that comes later (rviz2) gets the newest map at once; a large map is never queued.
  if (message_type == MessageName<MapMessage>()) return Qos::Latched();
  return Qos::Default();
}

void RegisterDdsTransport(runtime::ComponentRegistry& registry) {
  components::RegisterMessages();
  runtime::TopicTransport transport;
  transport.name = "dds";
  transport.make_reader =
      [](const runtime::TopicEndpoint& endpoint) -> std::unique_ptr<runtime::Component> {
    Endpoint e = Resolve(endpoint, {"qos", "wait_s", "start_wait_s", "tf", "targets", "lockstep"});
    // In lockstep a step waits for its answer: 10 s unless the file says.
    const double wait_s = e.options.lockstep && !endpoint.options.contains("wait_s")
                              ? kLockstepWaitS
                              : Seconds(endpoint.options, "wait_s", endpoint.where);
    const double start_wait_s = Seconds(endpoint.options, "start_wait_s", endpoint.where);
    auto reader = Reader::Create(e.participant, endpoint.message_type, e.options);
    return Dispatch(endpoint.message_type, [&](auto tag) -> std::unique_ptr<runtime::Component> {
      using M = decltype(tag);
      return std::make_unique<TopicReaderComponent<M>>(std::move(reader), wait_s, start_wait_s,
                                                       OnStamps(endpoint), e.options.lockstep);
    });
  };
  transport.attach_writer =
      [](const runtime::TopicEndpoint& endpoint,
         runtime::OutputBase& output) -> std::function<void(const runtime::StepContext&)> {
    Endpoint e = Resolve(endpoint, {"qos", "start_wait_s", "tf", "targets", "lockstep",
                                    "compressed", "jpeg_quality", kRobotDescription});
    const double start_wait_s = Seconds(endpoint.options, "start_wait_s", endpoint.where);
    std::shared_ptr<Writer> writer =
        Writer::Create(e.participant, endpoint.message_type, e.options);
    return Dispatch(endpoint.message_type, [&](auto tag) {
      return AttachWriter<decltype(tag)>(writer, start_wait_s, e.options.lockstep, output);
    });
  };
  // A pipeline that times its own steps (no clock.source) publishes its clock on /clock at the
  // start of each step, before its components: a ROS 2 node with use_sim_time sees the time of
  // the messages that follow (Gazebo's /clock).
  transport.attach_pipeline =
      [](const runtime::PipelineSpec& spec) -> std::function<void(const runtime::StepContext&)> {
    TransportNames names;
    const DomainOptions domain = ParseTransport(spec.transport, nullptr, &names);
    if (!spec.clock.source.empty() || names.clock_topic.empty()) return {};
    std::shared_ptr<ClockWriter> clock = ClockWriter::Create(
        SharedParticipant(domain), names.clock_topic, names.wall_stamps ? WallStampOffsetNs() : 0);
    return [clock](const runtime::StepContext& context) { clock->Publish(context.time); };
  };
  registry.SetTopicTransport(std::move(transport));
}

}  // namespace saccade::dds
