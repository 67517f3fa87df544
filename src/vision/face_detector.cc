#include "saccade/vision/face_detector.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "internal_cv.h"
#include "saccade/core/error.h"

namespace saccade::vision {
namespace {

void LoadCascade(const std::string& path, const char* key, cv::CascadeClassifier* cascade) {
  if (!std::filesystem::is_regular_file(path)) {
    throw FileError(path, 0, key, "no such file: expected an OpenCV Haar cascade (XML)");
  }
  bool ok = false;
  try {
    ok = cascade->load(path);
  } catch (const cv::Exception& e) {
    throw FileError(path, 0, key, std::string("not an OpenCV cascade: ") + e.what());
  }
  if (!ok || cascade->empty()) {
    throw FileError(path, 0, key,
                    "not an OpenCV cascade classifier (cv::CascadeClassifier::load failed)");
  }
}

}  // namespace

bool FaceDetector::Options::IsValid(std::string* error) const {
  std::string what;
  if (cascade_path.empty()) {
    what = "cascade_path is empty, expected the path of a face cascade";
  } else if (!std::isfinite(scale_factor) || scale_factor <= 1.0 || scale_factor > 4.0) {
    what = "scale_factor " + std::to_string(scale_factor) + ", expected 1 < scale_factor <= 4";
  } else if (min_neighbors < 0) {
    what = "min_neighbors " + std::to_string(min_neighbors) + ", expected >= 0";
  } else if (min_size_px < 1) {
    what = "min_size_px " + std::to_string(min_size_px) + ", expected >= 1";
  } else if (max_size_px != 0 && max_size_px < min_size_px) {
    what = "max_size_px " + std::to_string(max_size_px) +
           ", expected 0 (no limit) or >= " + "min_size_px (" + std::to_string(min_size_px) + ")";
  } else if (cat_min_neighbors < 0) {
    what = "cat_min_neighbors " + std::to_string(cat_min_neighbors) + ", expected >= 0";
  } else if (min_eyes < 1 || min_eyes > 2) {
    what = "min_eyes " + std::to_string(min_eyes) + ", expected 1 or 2";
  }
  if (what.empty()) return true;
  if (error) *error = "FaceDetector::Options: " + what;
  return false;
}

FaceDetector::FaceDetector() : FaceDetector(Options()) {}

FaceDetector::FaceDetector(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
  LoadCascade(options.cascade_path, "cascade_path", &face_);
  if (!options.cat_cascade_path.empty()) {
    LoadCascade(options.cat_cascade_path, "cat_cascade_path", &cat_);
  }
  if (!options.eye_cascade_path.empty()) {
    LoadCascade(options.eye_cascade_path, "eye_cascade_path", &eye_);
  }
}

std::vector<FaceDetection> FaceDetector::Detect(const Image& image) {
  cv::Mat gray = internal::ToGray(image, "FaceDetector::Detect");
  if (options_.equalize_histogram) {
    cv::Mat equalized;
    cv::equalizeHist(gray, equalized);
    gray = equalized;
  }
  std::vector<cv::Rect> boxes;
  std::vector<int> neighbors;
  const cv::Size min_size(options_.min_size_px, options_.min_size_px);
  const cv::Size max_size =
      options_.max_size_px > 0 ? cv::Size(options_.max_size_px, options_.max_size_px) : cv::Size();
  face_.detectMultiScale(gray, boxes, neighbors, options_.scale_factor, options_.min_neighbors, 0,
                         min_size, max_size);
  std::vector<FaceDetection> out(boxes.size());
  const cv::Rect image_rect(0, 0, gray.cols, gray.rows);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    FaceDetection& d = out[i];
    d.box = boxes[i];
    d.neighbors = i < neighbors.size() ? neighbors[i] : 0;
    if (!cat_.empty()) {
      // The cat cascade is trained on tighter, lower boxes than the face cascade's: search a
      // box enlarged by half on each side, for cat faces at least half the candidate's size.
      const int mx = d.box.width / 2, my = d.box.height / 2;
      const cv::Rect roi =
          cv::Rect(d.box.x - mx, d.box.y - my, d.box.width + 2 * mx, d.box.height + 2 * my) &
          image_rect;
      std::vector<cv::Rect> cats;
      cat_.detectMultiScale(gray(roi), cats, 1.05, options_.cat_min_neighbors, 0,
                            cv::Size(d.box.width / 2, d.box.height / 2));
      if (!cats.empty()) {
        d.rejected = true;
        d.reason = "cat face: " + std::to_string(cats.size()) + " hit(s) of the cat cascade";
        continue;
      }
    }
    if (!eye_.empty()) {
      // Eyes lie in the upper part of a frontal face.
      const cv::Rect upper =
          cv::Rect(d.box.x, d.box.y, d.box.width, d.box.height * 6 / 10) & image_rect;
      std::vector<cv::Rect> eyes;
      eye_.detectMultiScale(gray(upper), eyes, 1.05, 3, 0,
                            cv::Size(std::max(8, d.box.width / 8), std::max(8, d.box.width / 8)));
      if (static_cast<int>(eyes.size()) < options_.min_eyes) {
        d.rejected = true;
        d.reason = "no eyes: " + std::to_string(eyes.size()) + " eye(s) found, expected " +
                   std::to_string(options_.min_eyes);
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const FaceDetection& a, const FaceDetection& b) {
    return a.box.area() > b.box.area();
  });
  return out;
}

}  // namespace saccade::vision
