#include "saccade/components/demo/recording.h"

#include <fmt/format.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "saccade/core/error.h"

namespace saccade::components::demo {

namespace fs = std::filesystem;

cv::Mat Compose(const Latest& latest, double time, const std::string& status) {
  cv::Mat left = Annotate(latest, "left", 0.5);
  cv::Mat right = Annotate(latest, "right", 0.5);
  if (right.rows != left.rows) cv::resize(right, right, cv::Size(right.cols, left.rows));
  cv::Mat both;
  cv::hconcat(left, right, both);
  cv::Mat out(both.rows + 36, both.cols, CV_8UC3, cv::Scalar(30, 30, 30));
  both.copyTo(out(cv::Rect(0, 36, both.cols, both.rows)));
  cv::putText(out, fmt::format("t = {:6.2f} s   {}", time, status), cv::Point(10, 25),
              cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(255, 255, 255), 2);
  return out;
}

Recorder::Recorder(const fs::path& dir, double fps, bool force) : dir_(dir), fps_(fps) {
  if (fs::exists(dir) && !fs::is_directory(dir)) {
    throw InvalidArgument("demo: --record " + dir.string() + ": exists and is not a folder");
  }
  const bool used = fs::exists(dir / "summary.json") || fs::exists(dir / "frames") ||
                    fs::exists(dir / "demo.avi");
  if (used && !force) {
    throw InvalidArgument("demo: --record " + dir.string() +
                          " already holds a recording; pass --force to replace it");
  }
  if (used) {
    fs::remove_all(dir / "frames");
    fs::remove(dir / "demo.avi");
    fs::remove(dir / "summary.json");
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().filename().string().rfind("fixation_", 0) == 0) fs::remove(entry.path());
    }
  }
  fs::create_directories(dir / "frames");
}

Recorder::~Recorder() { writer_.release(); }

void Recorder::Write(int64_t step, const cv::Mat& bgr) {
  // Written whole or not at all (a temporary file renamed into place): a recording cut by a
  // kill keeps only whole frames.
  const fs::path frame = dir_ / "frames" / fmt::format("{:06d}.jpg", step);
  const fs::path partial = dir_ / "frames" / fmt::format(".{:06d}.tmp.jpg", step);
  if (!cv::imwrite(partial.string(), bgr, {cv::IMWRITE_JPEG_QUALITY, 85})) {
    throw Error("demo: cannot write " + frame.string());
  }
  fs::rename(partial, frame);
  if (!writer_.isOpened()) {
    // OpenCV's own AVI writer, not FFmpeg's or GStreamer's: it writes each frame's chunk as it
    // comes (through a buffer of about 32 KB, less than one frame), so a recording cut by a kill
    // plays back up to its last frame or two in players that read an AVI without its index
    // (FFmpeg, VLC, mpv); the others buffered many frames, or everything, until closed.
    writer_.open((dir_ / "demo.avi").string(), cv::CAP_OPENCV_MJPEG,
                 cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps_, bgr.size());
    if (!writer_.isOpened()) {
      throw Error("demo: cannot write " + (dir_ / "demo.avi").string() +
                  " (OpenCV's MJPEG writer failed)");
    }
  }
  writer_.write(bgr);
  ++frames_;
}

void Recorder::WriteFixation(int index, const std::string& object, const cv::Mat& bgr) {
  cv::imwrite((dir_ / fmt::format("fixation_{}_{}.png", index, object)).string(), bgr);
}

void Recorder::WriteSummary(const nlohmann::json& summary) {
  const fs::path tmp = dir_ / ".summary.json.tmp";
  {
    std::ofstream out(tmp);
    out << summary.dump(2) << "\n";
    if (!out) throw FileError(tmp.string(), 0, "", "cannot write");
  }
  fs::rename(tmp, dir_ / "summary.json");
}

}  // namespace saccade::components::demo
