// Recordings in MCAP: `--record FILE.mcap` on the commands that run a pipeline (demo, gui, run:
// record/recorder.h, with the scene's ground truth beside), and `saccade mcap info` on a
// recording.
#include <fmt/format.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "commands.h"
#include "saccade/components/demo/face_truth.h"
#include "saccade/components/roles.h"
#include "saccade/core/error.h"
#include "saccade/record/mcap.h"
#include "saccade/record/recorder.h"

namespace saccade::app {

namespace fs = std::filesystem;
using nlohmann::json;

bool IsMcapPath(const std::string& path) { return fs::path(path).extension() == ".mcap"; }

void AddRecordTuning(CLI::App* command, McapOptions& o) {
  command
      ->add_option("--record-chunk-s", o.chunk_s,
                   "MCAP recordings: seconds of the run's clock per chunk; a recording killed "
                   "at any moment loses at most the open chunk (> 0)")
      ->capture_default_str();
  command
      ->add_option("--record-compression", o.compression,
                   "MCAP recordings: chunk compression, zstd or none")
      ->check(CLI::IsMember({"zstd", "none"}))
      ->capture_default_str();
}

std::map<std::string, std::string> RunMetadata(const std::string& command,
                                               const std::string& pipeline,
                                               const std::string& scene, const std::string& head,
                                               const std::string& hardware) {
  std::map<std::string, std::string> m = {{"command", command}};
  if (!pipeline.empty()) m["pipeline"] = pipeline;
  if (!scene.empty()) m["scene"] = scene;
  if (!head.empty()) m["head_file"] = head;
  if (!hardware.empty()) m["hardware"] = hardware;
  return m;
}

struct Recording::Truth {
  const scene::Scene* scene = nullptr;  // the cameras' (the pipeline's resource)
  std::vector<components::demo::PictureFace> faces;
};

Recording::Recording(const McapOptions& o, runtime::Pipeline& pipeline,
                     std::map<std::string, std::string> metadata) {
  if (!IsMcapPath(o.path)) {
    throw InvalidArgument("--record " + o.path + ": an MCAP recording's name ends in .mcap");
  }
  if (fs::exists(o.path) && !o.force) {
    throw InvalidArgument("--record " + o.path +
                          ": the file exists; --force replaces it (nothing was written)");
  }
  if (!(o.chunk_s > 0.0)) {
    throw InvalidArgument(fmt::format("--record-chunk-s: expected > 0 s, got {}", o.chunk_s));
  }
  record::RecorderOptions r;
  r.compression = o.compression;
  r.chunk_seconds = o.chunk_s;
  if (auto* cameras = pipeline.FindRole<components::EyeCamerasRole>()) {
    const scene::Scene& scene = cameras->scene();
    if (scene.robot()) metadata["head"] = scene.robot()->head.name();
    metadata["cameras"] = cameras->rendered() != nullptr ? "rendered" : "real";
    if (cameras->rendered() != nullptr) {
      // The scene's ground truth beside the run: its objects' poses and its faces' centres.
      truth_ = std::make_unique<Truth>();
      truth_->scene = &scene;
      truth_->faces = components::demo::FindPictureFaces(scene);
    }
  }
  r.metadata = std::move(metadata);
  recorder_ = std::make_unique<record::PipelineRecorder>(pipeline, o.path, r);
}

Recording::~Recording() = default;

void Recording::AfterStep(const runtime::StepContext& context) {
  if (truth_) {
    const scene::Scene& scene = *truth_->scene;
    json objects = json::array();
    for (const scene::Object& object : scene.objects()) {
      const geometry::Pose X_WO = object.motion.PoseAt(context.time);
      const Eigen::Quaterniond q(X_WO.rotation());
      const Eigen::Vector3d p = X_WO.translation();
      objects.push_back({{"name", object.name},
                         {"id", object.id},
                         {"p_W", {p.x(), p.y(), p.z()}},
                         {"q_WO", {q.x(), q.y(), q.z(), q.w()}}});
    }
    json faces = json::array();
    for (const components::demo::PictureFace& face : truth_->faces) {
      if (!face.has_face) continue;
      const Eigen::Vector3d p = components::demo::FaceCentreAt(scene, face, context.time);
      faces.push_back({{"object", face.name}, {"p_W", {p.x(), p.y(), p.z()}}});
    }
    recorder_->AddJson("/saccade/ground_truth", context.time,
                       {{"time", context.time}, {"objects", objects}, {"faces", faces}});
  }
  recorder_->AfterStep(context);
}

std::string Recording::Close() {
  const record::RecordingStats s = recorder_->Close();
  return fmt::format("record: {} steps, {} messages, {:.1f} MB in {}\n", s.steps, s.messages,
                     static_cast<double>(s.bytes) / 1e6, recorder_->path().string());
}

}  // namespace saccade::app

namespace saccade::app {
namespace {

struct McapCommandOptions {
  std::string file;
  bool json = false;
};

json InfoJson(const std::string& file) {
  const record::McapReader reader(file);
  const record::McapStatistics& s = reader.statistics();
  const double duration =
      s.message_count == 0 ? 0.0
                           : static_cast<double>(s.message_end_time - s.message_start_time) * 1e-9;
  json channels = json::array();
  for (const auto& [id, channel] : reader.channels()) {
    const auto schema = reader.schemas().find(channel.schema_id);
    const auto count = s.channel_message_counts.find(id);
    const uint64_t n = count == s.channel_message_counts.end() ? 0 : count->second;
    channels.push_back(
        {{"topic", channel.topic},
         {"type",
          schema == reader.schemas().end() ? channel.message_encoding : schema->second.name},
         {"encoding", channel.message_encoding},
         {"messages", n},
         // n messages span n - 1 periods
         {"hz", duration > 0.0 && n > 1 ? static_cast<double>(n - 1) / duration : 0.0}});
  }
  json metadata = json::object();
  for (const record::McapMetadata& m : reader.metadata()) metadata[m.name] = m.values;
  return {{"file", file},
          {"bytes", fs::file_size(file)},
          {"profile", reader.profile()},
          {"library", reader.library()},
          {"complete", !reader.recovered()},
          {"lost_bytes", reader.lost_bytes()},
          {"messages", s.message_count},
          {"chunks", s.chunk_count},
          {"start_s", static_cast<double>(s.message_start_time) * 1e-9},
          {"duration_s", duration},
          {"metadata", metadata},
          {"channels", channels}};
}

std::string InfoText(const json& info) {
  std::string text = fmt::format(
      "{}: {:.1f} MB, {} messages in {} chunks over {:.2f} s (from {:.2f} s){}\n",
      info["file"].get<std::string>(), info["bytes"].get<double>() / 1e6,
      info["messages"].get<uint64_t>(), info["chunks"].get<uint64_t>(),
      info["duration_s"].get<double>(), info["start_s"].get<double>(),
      info["complete"].get<bool>()
          ? ""
          : fmt::format("\n  cut short (no summary): the complete chunks were recovered, the "
                        "last {} bytes lost",
                        info["lost_bytes"].get<uint64_t>()));
  text += fmt::format("  written by {} (profile {})\n", info["library"].get<std::string>(),
                      info["profile"].get<std::string>());
  for (const auto& [name, values] : info["metadata"].items()) {
    for (const auto& [key, value] : values.items()) {
      text += fmt::format("  {}.{}: {}\n", name, key, value.get<std::string>());
    }
  }
  std::size_t width = 5;
  for (const json& c : info["channels"])
    width = std::max(width, c["topic"].get<std::string>().size());
  text += fmt::format("  {:<{}}  {:<30}  {:>8}  {:>7}\n", "topic", width, "type", "messages", "Hz");
  for (const json& c : info["channels"]) {
    text += fmt::format("  {:<{}}  {:<30}  {:>8}  {:>7.2f}\n", c["topic"].get<std::string>(), width,
                        c["type"].get<std::string>(), c["messages"].get<uint64_t>(),
                        c["hz"].get<double>());
  }
  return text;
}

}  // namespace

Runner AddMcapCommand(CLI::App& app) {
  auto o = std::make_shared<McapCommandOptions>();
  auto* mcap = app.add_subcommand(
      "mcap",
      "Recordings in MCAP (`--record FILE.mcap` on demo, gui and run): what one holds. The files "
      "open in Foxglove, Lichtblick and rosbag2 (`ros2 bag info`) too.");
  mcap->require_subcommand(1);
  auto* info = mcap->add_subcommand(
      "info",
      "Topics, message types, counts and rates, duration, chunks, and the head, scene and "
      "pipeline the recording came from; a recording cut short (a killed run) is read from its "
      "complete chunks, and says how many bytes were lost");
  info->add_option("file", o->file, "The recording (.mcap)")->required();
  info->add_flag("--json", o->json, "Print it as JSON");
  return [o] {
    const json report = InfoJson(o->file);
    fmt::print("{}", o->json ? report.dump(2) + "\n" : InfoText(report));
    return 0;
  };
}

}  // namespace saccade::app
