#pragma once
// Face detection with OpenCV's Haar or LBP cascades (opencv-data), as the seed's perception
// stage, on the image or a reduced level of its pyramid (cheaper by about 4x a level),
// with a rejection of what only looks like a human face: Haar face cascades also fire on
// the cat (scenes/portraits.yaml's chelsea) and on other textures. Each candidate the face
// cascade finds is checked by OpenCV's cat-face cascade run around its box (a hit rejects it:
// "cat face") and by an eye cascade in its upper part (no eye rejects it: "no eyes").
// Rejected candidates are reported, flagged with the reason, not dropped.
#include <opencv2/core.hpp>
#include <opencv2/objdetect.hpp>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/core/interval.h"

namespace saccade::vision {

/// One face candidate in one image.
struct FaceDetection {
  cv::Rect box;       ///< pixels, in the image the detector saw
  int neighbors = 0;  ///< raw cascade hits merged into this box: the detector's confidence
  bool rejected = false;
  std::string reason;  ///< why it was rejected ("" when not)
  /// The index in FaceDetector::Search::checked of the box, checked on an earlier frame, whose
  /// verdict (rejected, reason) this one took; -1: the cat and eye cascades ran on this one.
  int verdict_from = -1;
  cv::Point2d Center() const {
    return {box.x + (box.width - 1) / 2.0, box.y + (box.height - 1) / 2.0};
  }
};

/// The face cascades opencv-data ships.
inline constexpr const char* kHaarFaceCascade =
    "/usr/share/opencv4/haarcascades/haarcascade_frontalface_alt2.xml";
inline constexpr const char* kLbpFaceCascade =
    "/usr/share/opencv4/lbpcascades/lbpcascade_frontalface_improved.xml";

/// Cascade face detector with a cat/eye rejection. Not thread-safe (OpenCV's
/// CascadeClassifier keeps state); use one per thread.
class FaceDetector {
 public:
  struct Options {
    /// The face cascade (OpenCV XML). alt2 is the default: on the eye cameras' rendered
    /// portraits (scenes/portraits.yaml, faces ~90 px) it finds the astronaut in both eyes with
    /// ~30 merged hits and no false positive that survives the eye check; `default` finds her
    /// with ~40 hits but adds a 113 px false box beside her face (rejected by the eye check);
    /// `alt` ~25 hits.
    std::string cascade_path = kHaarFaceCascade;
    /// Search the face cascade on pyramid level k (the image halved k times, cv::pyrDown);
    /// boxes come back in the image's pixels, and the cat and eye checks run on the image
    /// itself. 0 .. 4; sizes (min_size_px, max_size_px) stay in the image's pixels.
    int pyramid_level = 0;
    double scale_factor = 1.1;  ///< between pyramid levels: kScaleFactors
    int min_neighbors = 3;      ///< hits needed to keep a box: kNeighbors
    int min_size_px = 30;       ///< smallest face side, pixels: kMinSizes
    int max_size_px = 0;        ///< largest face side, pixels; 0: no limit (else >= min)
    /// cv::equalizeHist before detection. Off by default: on the rendered portraits it
    /// halves alt2's hits on the true face (3 instead of ~30) and loses it at min_neighbors 3.
    bool equalize_histogram = false;
    /// Reject candidates on which this cascade fires inside the box enlarged by half its
    /// size on each side; "" disables. It catches boxes framing a whole cat head (measured:
    /// `alt` at min_neighbors 1 boxes chelsea's head at ~290 px); smaller boxes on parts of
    /// the cat are left to the eye check.
    std::string cat_cascade_path =
        "/usr/share/opencv4/haarcascades/haarcascade_frontalcatface_extended.xml";
    int cat_min_neighbors = 3;  ///< kNeighbors
    /// Reject candidates in whose upper 60 % this cascade finds fewer than `min_eyes` eyes;
    /// "" disables. Measured on the rendered portraits: the astronaut's face has them; the
    /// boxes the face cascades put on the cat and every other false box have none.
    std::string eye_cascade_path = "/usr/share/opencv4/haarcascades/haarcascade_eye.xml";
    int min_eyes = 1;  ///< kEyes: 1 or 2

    // The valid values, stated once: IsValid checks them, and vision.face_detector declares
    // its parameters with them (runtime::ParamDecl::Range(const Interval&)).
    static constexpr Interval kPyramidLevels = Interval::Closed(0, 4);
    static constexpr Interval kScaleFactors = Interval::LeftOpen(1, 4);
    static constexpr Interval kNeighbors = Interval::Closed(0, 1000);
    static constexpr Interval kMinSizes = Interval::Closed(1, 100000);
    /// max_size_px: 0 (no limit) or in [min_size_px, 100000].
    static constexpr Interval kMaxSizes = Interval::Closed(0, 100000);
    static constexpr Interval kEyes = Interval::Closed(1, 2);

    bool IsValid(std::string* error) const;
  };

  /// Loads the cascades. Throws InvalidArgument with IsValid's message, FileError naming the
  /// path when a cascade file is missing or not a cascade.
  FaceDetector();  ///< default Options
  explicit FaceDetector(const Options& options);

  /// Candidates in an rgb8, rgba8 or gray8 image, largest first, rejected ones included and
  /// flagged. Throws InvalidArgument for another format (a wiring error).
  std::vector<FaceDetection> Detect(const Image& image);
  /// The same, searching faces only inside `regions` (image pixels, clipped to it); an empty
  /// list searches nothing. Boxes found in overlapping regions are merged.
  std::vector<FaceDetection> Detect(const Image& image, const std::vector<cv::Rect>& regions);

  /// What one call searches, for a caller that knows more than the options: a tracker's
  /// window gives where the face is, its size to within a factor, and its verdict.
  struct Search {
    /// Image pixels, clipped to it; an empty list searches nothing.
    std::vector<cv::Rect> regions;
    /// Face sides searched (image pixels), within the options' min_size_px and max_size_px;
    /// 0: the options' bound alone.
    int min_size_px = 0;
    int max_size_px = 0;
    /// Candidates checked on an earlier frame: a box that overlaps one of them by at least
    /// kVerdictOverlap of their union takes its verdict instead of running the cat and eye
    /// cascades again (they are most of the cost of a search around a tracked face).
    std::vector<FaceDetection> checked;
    /// The overlap (of the union) at which a box takes a checked candidate's verdict; of
    /// several, the one it overlaps most.
    double verdict_overlap = kVerdictOverlap;
  };
  static constexpr double kVerdictOverlap = 0.7;
  std::vector<FaceDetection> Detect(const Image& image, const Search& search);

  const Options& options() const { return options_; }

 private:
  // `gray`: the whole image in gray; or, with `colour` (a colour image, no equalisation, level
  // 0), empty, and only the rectangles searched and checked are converted from `colour`.
  std::vector<FaceDetection> DetectIn(const cv::Mat& gray, const Search& search,
                                      const cv::Mat* colour = nullptr);

  Options options_;
  cv::CascadeClassifier face_;
  cv::CascadeClassifier cat_;
  cv::CascadeClassifier eye_;
};

}  // namespace saccade::vision
