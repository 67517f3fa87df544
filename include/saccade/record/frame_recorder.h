#pragma once
// `saccade render --record FILE.mcap`: rendered frames to MCAP, named as a pipeline's
// recording names them (recorder.h), so that one reader, `saccade mcap export` and
// `--play` take either:
//
//   each camera's image          <ns>/<camera>/image_raw         sensor_msgs/msg/Image
//                                <ns>/<camera>/camera_info       sensor_msgs/msg/CameraInfo
//                                /tf                             its optical frame
//   with depth truth             <ns>/<camera>/depth/image_raw   Image, 32FC1, metres (z)
//   with id truth                <ns>/<camera>/ids/image_raw     Image, mono16, instance ids
//   the head's joints            <ns>/joint_states, joint_targets, robot_description, /tf
//   each frame's record          <ns>/frames                     JSON: frames.jsonl's line
//                                                                (render/dataset.h), without
//                                                                file names
//
// Log times are the frames' times (frame i at i / fps); publish times their capture stamps.
// Frames are written as they come, on the caller's thread; a render killed at any moment
// leaves its complete chunks, as any recording.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "saccade/record/recorder.h"
#include "saccade/render/dataset.h"
#include "saccade/scene/scene.h"

namespace saccade::record {

class FrameRecorder final : public render::FrameSink {
 public:
  /// Creates (replaces) `path`; `scene` must outlive the recorder. Throws saccade::FileError
  /// when the file cannot be written, InvalidArgument for options out of range.
  FrameRecorder(const scene::Scene& scene, const render::TruthRequest& truth,
                const std::filesystem::path& path, RecorderOptions options = {});
  /// Without Close: the file is left without its summary, as a killed recording.
  ~FrameRecorder() override;
  FrameRecorder(const FrameRecorder&) = delete;
  FrameRecorder& operator=(const FrameRecorder&) = delete;

  void Write(int64_t index, double time, const scene::SceneState& state,
             const std::vector<render::Frame>& frames) override;
  /// Writes the summary and closes the file.
  RecordingStats Close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace saccade::record
