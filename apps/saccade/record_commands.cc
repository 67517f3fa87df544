// Recordings in MCAP: `--record FILE.mcap` on the commands that run a pipeline (demo, gui, run:
// record/recorder.h, with the scene's ground truth beside), and `saccade mcap info` on a
// recording.
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>

#include "commands.h"
#include "saccade/components/demo/face_truth.h"
#include "saccade/components/roles.h"
#include "saccade/core/error.h"
#include "saccade/geometry/json.h"
#include "saccade/geometry/pose.h"
#include "saccade/record/mcap.h"
#include "saccade/record/recorder.h"
#include "saccade/record/ros_message.h"
#include "saccade/render/dataset.h"

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
  command
      ->add_option("--record-zstd-level", o.zstd_level,
                   "MCAP recordings: zstd's level, -7..-1 (faster, larger) or 1..19 (slower, "
                   "smaller)")
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

record::RecorderOptions RecorderOptionsFor(const McapOptions& o) {
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
  if (o.zstd_level < -7 || o.zstd_level > 19 || o.zstd_level == 0) {
    throw InvalidArgument(
        fmt::format("--record-zstd-level: expected -7..-1 or 1..19, got {}", o.zstd_level));
  }
  record::RecorderOptions r;
  r.compression = o.compression;
  r.chunk_seconds = o.chunk_s;
  r.zstd_level = o.zstd_level;
  return r;
}

Recording::Recording(const McapOptions& o, runtime::Pipeline& pipeline,
                     std::map<std::string, std::string> metadata) {
  record::RecorderOptions r = RecorderOptionsFor(o);
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

std::string Recording::file() const { return recorder_->path().string(); }
uint64_t Recording::bytes() const { return recorder_->stats().bytes; }

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
  std::string out;  // export
  bool force = false;
};

// The pose of a geometry_msgs/Transform as decoded, in saccade's one JSON form of a pose.
json PoseJson(const json& transform) {
  const json& t = transform["translation"];
  const json& r = transform["rotation"];
  const Eigen::Quaterniond q(r["w"].get<double>(), r["x"].get<double>(), r["y"].get<double>(),
                             r["z"].get<double>());
  return JsonCodec<geometry::Pose>::Encode(
      geometry::MakePose(q.normalized().toRotationMatrix(),
                         {t["x"].get<double>(), t["y"].get<double>(), t["z"].get<double>()}));
}

int64_t StampNs(const json& header) {
  return header["stamp"]["sec"].get<int64_t>() * 1'000'000'000 +
         header["stamp"]["nanosec"].get<int64_t>();
}

// `saccade mcap export`: the recording's images as a data set folder, as `saccade render`
// writes one (render/dataset.h): DIR/<camera>/NNNNNN.png and DIR/frames.jsonl.
class Exporter {
 public:
  Exporter(const std::string& file, const fs::path& out, bool force) : reader_(file), out_(out) {
    if (fs::exists(out / "frames.jsonl") && !force) {
      throw InvalidArgument("mcap export: " + (out / "frames.jsonl").string() +
                            " exists; --force replaces the data set (nothing was written)");
    }
    fs::create_directories(out);
    index_.open(out / "frames.jsonl.tmp");
    if (!index_) throw FileError((out / "frames.jsonl").string(), 0, "", "cannot be written");
    for (const auto& [id, channel] : reader_.channels()) {
      const auto schema = reader_.schemas().find(channel.schema_id);
      if (channel.message_encoding != "cdr" || schema == reader_.schemas().end() ||
          schema->second.encoding != "ros2msg") {
        continue;
      }
      decoders_.emplace(
          id, std::make_pair(schema->second.name,
                             record::RosMessageDecoder(schema->second.name, schema->second.data)));
    }
  }

  int Run() {
    reader_.ForEachMessage([&](const record::McapMessage& m) {
      const auto& channel = reader_.channels().at(m.channel_id);
      if (channel.message_encoding == "json" && channel.topic.ends_with("/frames")) {
        AddFrameRecord(json::parse(m.data.begin(), m.data.end(), nullptr, false));
        return true;
      }
      const auto decoder = decoders_.find(m.channel_id);
      if (decoder == decoders_.end()) return true;
      const std::string& type = decoder->second.first;
      if (type != "sensor_msgs/msg/Image" && type != "sensor_msgs/msg/CameraInfo" &&
          type != "tf2_msgs/msg/TFMessage" && type != "sensor_msgs/msg/JointState") {
        return true;
      }
      std::vector<std::span<const uint8_t>> blobs;
      const json v = decoder->second.second.Decode(m.data, &blobs);
      const std::string& topic = reader_.channels().at(m.channel_id).topic;
      if (type == "sensor_msgs/msg/CameraInfo") {
        infos_[v["header"]["frame_id"]] = v;
      } else if (type == "tf2_msgs/msg/TFMessage") {
        for (const json& t : v["transforms"]) poses_[t["child_frame_id"]] = t["transform"];
      } else if (type == "sensor_msgs/msg/JointState") {
        if (topic.ends_with("joint_states")) {
          joints_ = json::object();
          for (std::size_t i = 0; i < v["name"].size() && i < v["position"].size(); ++i) {
            joints_[v["name"][i].get<std::string>()] = v["position"][i];
          }
        }
      } else {
        AddImage(topic, v, blobs);
      }
      return true;
    });
    Flush();
    index_.close();
    fs::rename(out_ / "frames.jsonl.tmp", out_ / "frames.jsonl");
    return frames_;
  }

 private:
  // An image: the camera's (<camera>/image_raw) to <camera>/NNNNNN.png, its depth truth
  // (<camera>/depth/image_raw, 32FC1 metres) to <camera>/depth/ as 16-bit millimetres and its
  // id truth (<camera>/ids/image_raw, mono16) to <camera>/ids/ and its raw colour filter mosaic
  // (<camera>/raw/image_raw, bayer_*8) to <camera>/raw/ as 8-bit grey, as `saccade render`
  // writes them.
  void AddImage(const std::string& topic, const json& image,
                const std::vector<std::span<const uint8_t>>& blobs) {
    const int64_t stamp = StampNs(image["header"]);
    if (!frame_.empty() && stamp != frame_stamp_) Flush();
    frame_stamp_ = stamp;
    const std::string truth = topic.ends_with("/depth/image_raw") ? "depth"
                              : topic.ends_with("/ids/image_raw") ? "ids"
                              : topic.ends_with("/raw/image_raw") ? "raw"
                                                                  : "";
    std::string frame_id = image["header"]["frame_id"];
    std::string camera = frame_id;
    if (camera.size() > 8 && camera.ends_with("_optical")) {
      camera.resize(camera.size() - 8);
    }
    const std::string encoding = image["encoding"];
    const int width = image["width"], height = image["height"];
    const std::size_t step = image["step"];
    int cv_type = 0;
    if (encoding == "rgb8" || encoding == "bgr8")
      cv_type = CV_8UC3;
    else if (encoding == "rgba8" || encoding == "bgra8")
      cv_type = CV_8UC4;
    else if (encoding == "mono8" || encoding == "8UC1")
      cv_type = CV_8UC1;
    else if (encoding == "mono16" || encoding == "16UC1")
      cv_type = CV_16UC1;
    else if (encoding == "32FC1" && truth == "depth")
      cv_type = CV_32FC1;
    else if (truth == "raw" && encoding.starts_with("bayer_") && encoding.ends_with("8"))
      cv_type = CV_8UC1;
    else {
      if (said_.insert(encoding).second) {
        fmt::print(stderr, "mcap export: {} images not exported (encoding {})\n", camera, encoding);
      }
      return;
    }
    const std::span<const uint8_t> pixels = blobs.at(image["data"]["blob"].get<std::size_t>());
    if (pixels.size() < step * static_cast<std::size_t>(height)) {
      throw InvalidArgument(fmt::format("mcap export: an image of {} holds {} bytes, not {}",
                                        camera, pixels.size(), step * height));
    }
    cv::Mat mat(height, width, cv_type, const_cast<uint8_t*>(pixels.data()), step);
    cv::Mat out;
    if (encoding == "rgb8") {
      cv::cvtColor(mat, out, cv::COLOR_RGB2BGR);
    } else if (encoding == "rgba8") {
      cv::cvtColor(mat, out, cv::COLOR_RGBA2BGRA);
    } else if (cv_type == CV_32FC1) {
      const Image metres(width, height, PixelFormat::kFloat32, pixels.data(), step);
      const Image mm = render::DepthToMillimetres(metres);
      cv::Mat(height, width, CV_16UC1, const_cast<uint8_t*>(mm.data())).copyTo(out);
    } else {
      out = mat;
    }
    const std::string folder = truth.empty() ? camera : camera + "/" + truth;
    const std::string file = fmt::format("{}/{:06d}.png", folder, frames_);
    fs::create_directories(out_ / folder);
    if (!cv::imwrite((out_ / file).string(), out)) {
      throw FileError((out_ / file).string(), 0, "", "cannot be written");
    }
    json& entry = frame_[camera];
    if (!truth.empty()) {
      entry[truth] = file;
      // The filter's pattern, as frames.jsonl of `saccade render` names it ("rggb", ...).
      if (truth == "raw") entry["cfa"] = encoding.substr(6, 4);
      return;
    }
    entry["file"] = file;
    entry["width"] = width;
    entry["height"] = height;
    entry["encoding"] = encoding;
    if (const auto info = infos_.find(frame_id); info != infos_.end()) {
      const json& k = info->second["k"];
      entry["K"] = {{k[0], k[1], k[2]}, {k[3], k[4], k[5]}, {k[6], k[7], k[8]}};
      entry["distortion"] = {{"model", info->second["distortion_model"]},
                             {"coefficients", info->second["d"]}};
    }
    if (const auto pose = poses_.find(frame_id); pose != poses_.end()) {
      entry["X_WC"] = PoseJson(pose->second);
    }
    if (!joints_.empty()) entry["joints"] = joints_;
  }
  // A frame's record (render --record's /saccade/frames, written after the frame's images at
  // the same stamp): what the images cannot say, the motion-blur sub-frames and the camera
  // controls each was taken with, joins the frame's lines.
  void AddFrameRecord(const json& record) {
    if (!record.is_object() || !record.contains("cameras") || !record["cameras"].is_object()) {
      return;
    }
    for (const auto& [camera, entry] : record["cameras"].items()) {
      if (!frame_.contains(camera) || !entry.is_object()) continue;
      for (const char* key : {"exposure_samples", "exposure_s", "gain_db", "focus_m"}) {
        if (entry.contains(key)) frame_[camera][key] = entry[key];
      }
    }
  }
  void Flush() {
    if (frame_.empty()) return;
    index_ << json{{"frame", frames_},
                   {"time", static_cast<double>(frame_stamp_) * 1e-9},
                   {"cameras", frame_}}
                  .dump()
           << "\n";
    ++frames_;
    frame_ = json::object();
  }

  record::McapReader reader_;
  fs::path out_;
  std::ofstream index_;
  std::map<uint16_t, std::pair<std::string, record::RosMessageDecoder>> decoders_;
  std::map<std::string, json> infos_, poses_;  // by frame id
  json joints_ = json::object();
  json frame_ = json::object();
  int64_t frame_stamp_ = 0;
  int frames_ = 0;
  std::set<std::string> said_;
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
  auto* export_command = mcap->add_subcommand(
      "export",
      "The recording's images as a data set folder, the format `saccade render` writes: "
      "DIR/<camera>/NNNNNN.png and DIR/frames.jsonl, a line per frame (the images of one "
      "stamp) with each camera's file, size, K, distortion (ROS's model name and "
      "coefficients), X_WC (from /tf) and the joints");
  export_command->add_option("file", o->file, "The recording (.mcap)")->required();
  export_command->add_option("--out", o->out, "The data set folder")->required();
  export_command->add_flag("--force", o->force, "Replace a data set already in --out");
  return [o, info] {
    if (info->parsed()) {
      const json report = InfoJson(o->file);
      fmt::print("{}", o->json ? report.dump(2) + "\n" : InfoText(report));
      return 0;
    }
    Exporter exporter(o->file, o->out, o->force);
    const int frames = exporter.Run();
    fmt::print("{} frames -> {}\n", frames, o->out);
    return 0;
  };
}

}  // namespace saccade::app
