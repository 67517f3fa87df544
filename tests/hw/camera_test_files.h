#pragma once
// Shared by the camera source tests: OpenCV's sample stereo images (Debian's opencv-doc, read
// in place: none of the files used is gzipped there), a temporary folder per test, and
// frames written with OpenCV.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "saccade/core/image.h"

namespace saccade::hw::testing {

namespace fs = std::filesystem;

/// OpenCV's sample data: left01..14.jpg and right01..14.jpg (no 10), stereo_calib.xml (their
/// image list, alternating left and right), intrinsics.yml (M1 D1 M2 D2 of the pair, no image
/// size) and left_intrinsics.yml (the left camera alone, 640x480).
inline const fs::path kOpenCvData = "/usr/share/doc/opencv-doc/examples/data";

/// The image numbers of the 13 pairs, in stereo_calib.xml's order.
inline const std::vector<int> kPairNumbers = {1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14};

inline std::string SampleName(const char* side, int number) {
  char name[32];
  std::snprintf(name, sizeof(name), "%s%02d.jpg", side, number);
  return name;
}

/// A temporary folder for one test, removed afterwards.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string("saccade_camera_") + std::to_string(::getpid()) + "_" +
                       info->test_suite_name() + "_" + info->name();
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    dir_ = fs::temp_directory_path() / name;
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path Path(const std::string& name) const { return dir_ / name; }

  fs::path WriteText(const std::string& name, const std::string& text) const {
    const fs::path path = Path(name);
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }

  fs::path dir_;
};

/// A BGR test frame that differs from frame to frame and from pixel to pixel.
inline cv::Mat PatternFrame(int index, cv::Size size) {
  cv::Mat frame(size, CV_8UC3);
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      frame.at<cv::Vec3b>(y, x) =
          cv::Vec3b(static_cast<uint8_t>(x * 4 + index * 20), static_cast<uint8_t>(y * 4),
                    static_cast<uint8_t>(index * 37 + 5));
    }
  }
  return frame;
}

/// Writes PatternFrame(i) for i in [0, count) as <folder>/<prefix>_0000.png, ...; returns the
/// printf pattern.
inline std::string WriteSequence(const fs::path& folder, const std::string& prefix, int count,
                                 cv::Size size) {
  fs::create_directories(folder);
  for (int i = 0; i < count; ++i) {
    char name[64];
    std::snprintf(name, sizeof(name), "_%04d.png", i);
    cv::imwrite((folder / (prefix + name)).string(), PatternFrame(i, size));
  }
  return (folder / (prefix + "_%04d.png")).string();
}

/// The pixels of an RGB8 Image as a cv::Mat header (no copy).
inline cv::Mat MatOf(const Image& image) {
  return cv::Mat(image.height(), image.width(), CV_8UC3, const_cast<uint8_t*>(image.data()),
                 image.stride());
}

/// cv::imread (BGR) as RGB: the reference for a frame read from a file.
inline cv::Mat ImreadRgb(const fs::path& path) {
  const cv::Mat bgr = cv::imread(path.string(), cv::IMREAD_COLOR);
  cv::Mat rgb;
  if (!bgr.empty()) cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

/// The number of pixels where the two differ (0: identical); -1 when the sizes differ.
inline int64_t DifferentPixels(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return -1;
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  return cv::countNonZero(diff.reshape(1));
}

}  // namespace saccade::hw::testing
