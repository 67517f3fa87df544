#pragma once
// `saccade demo --record DIR`: the annotated frames of both eyes side by side with a status
// line, as DIR/frames/NNNNNN.jpg (each written whole: a temporary file renamed into place),
// DIR/demo.avi (MJPEG, OpenCV's own writer: a recording cut by a kill plays back up to its
// last frame or two, without the index that closing writes), one DIR/fixation_N_<object>.png per
// fixation, and DIR/summary.json.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>

#include "saccade/components/demo/overlay.h"

namespace saccade::components::demo {

/// Both eyes' annotated views at half size, side by side, under "t = 1.23 s   <status>".
cv::Mat Compose(const Latest& latest, double time, const std::string& status);

class Recorder {
 public:
  /// Creates `dir`; a folder that already holds a recording is refused with InvalidArgument
  /// unless `force`, which removes the old one first.
  Recorder(const std::filesystem::path& dir, double fps, bool force);
  ~Recorder();
  /// Throws Error when a frame or the video cannot be written.
  void Write(int64_t step, const cv::Mat& bgr);
  void WriteFixation(int index, const std::string& object, const cv::Mat& bgr);
  /// summary.json, atomically (a reader never sees half of it).
  void WriteSummary(const nlohmann::json& summary);
  int64_t frames() const { return frames_; }

 private:
  std::filesystem::path dir_;
  double fps_;
  cv::VideoWriter writer_;
  int64_t frames_ = 0;
};

}  // namespace saccade::components::demo
