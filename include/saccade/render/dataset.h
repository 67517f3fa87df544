#pragma once
// A stereo data set on disk, as `saccade render` writes it (docs/cli.md): for each camera
// DIR/<camera>/NNNNNN.png (and depth/, ids/ with ground truth), DIR/<camera>.yaml and
// DIR/stereo.yaml (OpenCV calibration files of the images as rendered), and DIR/frames.jsonl,
// one line per frame with every camera's file, K, distortion, X_WC, joints and object truth.
// A frame is listed in frames.jsonl only once all its images are written: a run that is
// killed leaves whole frames.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::render {

/// Which ground truth a data set holds.
struct TruthRequest {
  bool depth = false;  ///< depth/NNNNNN.png: 16-bit millimetres, 0 where no surface
  bool ids = false;    ///< ids/NNNNNN.png: 16-bit instance ids
  bool boxes = false;  ///< each object's 2D box, pixels and pose in frames.jsonl
  bool Any() const { return depth || ids || boxes; }
  /// "depth,ids,boxes" (any subset, any order). Throws InvalidArgument naming the bad item
  /// and the valid ones.
  static TruthRequest Parse(const std::string& list);
};

/// kFloat32 depth (metres) to kGray16 millimetres, as the data set's depth PNGs: rounded to
/// nearest, 0 where there is no surface, at least 1 where there is one, 65535 for 65.535 m
/// and beyond.
Image DepthToMillimetres(const Image& depth);
/// kUint32 instance ids to kGray16, as the data set's id PNGs; throws saccade::Error naming
/// `camera` for an id above 65535 (CheckIdsFitPng16 refuses such scenes before rendering).
Image IdsToPng16(const Image& ids, const std::string& camera);

/// Sets the renderer's truth outputs that `truth` needs.
void ApplyTruth(const TruthRequest& truth, RendererOptions* options);

/// The 16-bit id images hold ids up to 65535: throws InvalidArgument naming an object (or the
/// robot) with a larger id that the images could show, before anything is rendered.
void CheckIdsFitPng16(const scene::Scene& scene, const RendererOptions& options);

/// Where RenderDataset puts its frames: a data set folder (DatasetWriter), an MCAP recording
/// (record/frame_recorder.h), or both.
class FrameSink {
 public:
  virtual ~FrameSink() = default;
  /// One frame of every camera at `time`; `state` is the state it was rendered from.
  virtual void Write(int64_t index, double time, const scene::SceneState& state,
                     const std::vector<Frame>& frames) = 0;
};

/// One frame's record, as frames.jsonl holds it: {"frame", "time", "cameras": {name: {width,
/// height, K, distortion, X_WC, exposure_samples, exposure_s, gain_db, focus_m, joints, and
/// with `truth` the objects' boxes and poses}}}. `files`: each camera's image files too (file,
/// depth, ids).
nlohmann::json FrameRecord(int64_t index, double time, const std::vector<Frame>& frames,
                           const TruthRequest& truth, bool scene_has_objects, bool files);

/// Writes frames of `cameras` into the folder `out`.
class DatasetWriter final : public FrameSink {
 public:
  /// Creates `out` if missing. Output already there (frames.jsonl, a camera's folder or file)
  /// is refused with InvalidArgument unless `force`, which removes the old frames first; the
  /// hidden temporaries an interrupted run left (RemoveStaleTemporaries) are removed too.
  /// `distortion_on`: whether the renderer was asked for lens distortion (a warning is
  /// logged when a camera's frames come without it).
  DatasetWriter(const scene::Scene& scene, std::vector<std::string> cameras,
                const TruthRequest& truth, std::filesystem::path out, bool force,
                bool distortion_on);
  /// Writes one frame of every camera (the calibration files with the first) at `time`;
  /// `state` gives the stereo extrinsics. Throws FileError when a file cannot be written.
  void Write(int64_t index, double time, const scene::SceneState& state,
             const std::vector<Frame>& frames) override;
  int64_t written() const { return written_; }

 private:
  const scene::Scene& scene_;
  std::vector<std::string> cameras_;
  TruthRequest truth_;
  std::filesystem::path out_;
  bool distortion_on_;
  bool scene_has_objects_;
  std::ofstream index_;
  int64_t written_ = 0;
};

/// Renders `frames` frames at times i / fps from `initial` into `sink`, two in flight
/// (frame i + 1 is drawn while frame i is read back and written); stops after the frame in
/// hand once `stop` is set. `progress(done, frames per second)` after each frame. Returns
/// the number of whole frames written.
int RenderDataset(Renderer& renderer, FrameSink& sink, const scene::SceneState& initial, int frames,
                  double fps, const std::atomic<bool>& stop,
                  const std::function<void(int done, double fps)>& progress = {});

}  // namespace saccade::render
