#pragma once
// Recording a pipeline's run to MCAP (`--record FILE.mcap`): every output of every component,
// each step, as ROS 2 messages where saccade has a ROS 2 form for them (dds/topics.h: the same
// conversion and the same CDR serializer as the DDS writers) and as JSON otherwise (faces,
// tracks, selections: the messages' own JSON form, runtime/message.h). Topics, under the
// namespace (default /saccade), are those of `saccade run pipelines/robot.yaml` for the robot:
//
//   the eye cameras' images     <ns>/<camera>/image_raw     sensor_msgs/msg/Image
//                               <ns>/<camera>/camera_info   sensor_msgs/msg/CameraInfo
//                               /tf                         the optical frames (world -> ...)
//   the head's joints           <ns>/joint_states           sensor_msgs/msg/JointState
//                               <ns>/joint_targets          their targets (JointState)
//                               <ns>/robot_description      std_msgs/msg/String (URDF), once
//                               /tf                         every link (robot_state_publisher)
//   any other output            <ns>/<component>/<output>   its ROS 2 type, or JSON
//   AddJson's extra channels    as named (ground truth)     JSON
//
// Each message's log time is the time of the step in which it was sent (the run's clock:
// simulated seconds from 0, or wall seconds since the start in real time); its publish time is
// its capture stamp (header.stamp), or its `time` field for JSON messages. The file's Metadata
// record "saccade" holds RecorderOptions::metadata (the head, scene and pipeline of the run).
//
// The messages of a step are serialized, written and compressed on a thread of the recorder's
// own (SCHED_IDLE: it runs on a core the loop leaves idle), after the step: the loop waits only
// when that thread is two steps behind. A recording
// killed at any moment keeps every complete chunk (McapReader recovers them): what is lost is
// the open chunk, at most RecorderOptions::chunk_seconds of the run, and the at most two steps
// handed over and not yet written.
//
// Threads: components' outputs may emit from any thread during a step; the recorder is made,
// called (AfterStep, AddJson, Close) and destroyed on the thread that runs the pipeline, between
// steps (the GUI starts and stops recordings while the pipeline runs on).
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "saccade/runtime/component.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::record {

struct RecorderOptions {
  std::string compression = "zstd";  ///< "zstd" or "none"
  /// zstd's level: its fast levels by default, since rendered images with sensor noise hardly
  /// compress (bench/baselines/record-2core.md has the figures); -7 .. -1 or 1 .. 19.
  int zstd_level = -3;
  /// Crash safety: a chunk spans at most this much of the run's time (a recording killed at
  /// any moment loses at most the open chunk), s > 0.
  double chunk_seconds = 1.0;
  std::string ns = "/saccade";                  ///< the topics' namespace
  std::map<std::string, std::string> metadata;  ///< the "saccade" Metadata record
};

/// What a recording holds so far.
struct RecordingStats {
  int64_t steps = 0;
  uint64_t messages = 0;
  uint64_t bytes = 0;  ///< of the file
};

class PipelineRecorder {
 public:
  /// Creates (replaces) `path` and taps every output of `pipeline`, which must outlive the
  /// recorder. Throws saccade::FileError when the file cannot be written, InvalidArgument for
  /// options out of range.
  PipelineRecorder(runtime::Pipeline& pipeline, const std::filesystem::path& path,
                   RecorderOptions options = {});
  /// Leaves the pipeline's outputs as they were. Without Close: the steps handed over are
  /// written and the file is left without its summary, as a killed recording (readers recover
  /// its chunks).
  ~PipelineRecorder();
  PipelineRecorder(const PipelineRecorder&) = delete;
  PipelineRecorder& operator=(const PipelineRecorder&) = delete;

  /// After each step (runtime::RunOptions::after_step): hands what the outputs sent in it to
  /// the writing thread, logged at `context.time`. Throws saccade::FileError when writing an
  /// earlier step failed (a full disk).
  void AfterStep(const runtime::StepContext& context);
  /// A JSON message on a channel of its own (`topic`, created on first use), logged and
  /// published at `time` (s), written with the current step's messages (ground truth).
  void AddJson(const std::string& topic, double time, const nlohmann::json& message);
  /// Writes what is left, the summary and the footer. Idempotent. Throws as AfterStep.
  RecordingStats Close();
  RecordingStats stats() const;
  const std::filesystem::path& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saccade::record
