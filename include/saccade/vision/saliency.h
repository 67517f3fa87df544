#pragma once
// Spectral residual saliency (Hou & Zhang, "Saliency Detection: A Spectral Residual Approach",
// CVPR 2007): the first, cheap stage of a two-stage attention model (the seed's reference: the
// first stage finds zones of interest in the whole image at low resolution, the second processes
// only the most interesting zone at full resolution).
//
// On a grey image I (grey levels scaled to [0, 1]) downscaled by area averaging to
// `working_width` pixels across, the aspect ratio kept:
//   F = DFT(p),  P = arg F,  L = log(|F| + n)                  (Hou & Zhang eq. 5-7)
//   R = L - h3 * L          (h3: the 3 x 3 mean filter)         (eq. 8, the spectral residual)
//   S = g * |DFT^-1(exp(R + i P))|^2   (g: Gaussian, sigma = blur_sigma working pixels) (eq. 9)
// then S is scaled to [0, 1] (min to 0, max to 1) and resized (bilinear) to the input's size.
//
// Three departures from Hou's code, each for a failure it had:
// - p is the periodic component of I in Moisan's periodic plus smooth decomposition I = p + s
//   (J. Math. Imaging Vis. 39, 2011), not I itself. The DFT sees I repeated, and the jumps
//   between its opposite borders are edges the spectral residual finds salient: a photograph
//   had zones in its corners. p keeps every detail of I (s is smooth, harmonic inside).
// - n is the amplitude of 8-bit rounding noise at any frequency, sqrt(pixels / 12) / 255: below
//   it the spectrum says nothing, and a synthetic image's exact spectral zeros (log 0) ruled the
//   residual (a lone square on a flat field was not its top zone).
// - The scaling to [0, 1] makes the method blind to strength: it finds the rarest structure
//   however faint, and pure shading got peaks of 1 from rounding. So an image whose working
//   image has no curvature (|Laplacian| below kFlatLaplacian at every pixel off its border: a
//   constant, a linear ramp, a gentle vignette) has the all-zero map and no zone.
//
// Zones are the connected regions (8-connected) of the working map above zone_threshold times
// its mean (Hou & Zhang section 3.3 use 3 x the mean for their object map), ranked by their
// peak. What is salient is what is rare at the working scale: a lone object, but also the
// contour of a lone smooth bump, and in a cluttered photograph a strong edge may outrank a
// pasted object (tests/vision/saliency_test.cc measures how often). Images: row 0 at the top,
// pixel centres at integer coordinates.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/core/interval.h"

namespace saccade::vision {

/// A zone of interest in an image (pixel coordinates of the image given to Zones).
struct SaliencyZone {
  cv::Rect box;      ///< the zone's bounding box, inside the image
  cv::Point peak;    ///< the zone's most salient pixel (a local maximum of the map), in box
  double score = 0;  ///< the map's value at the peak, in (0, 1] (1 for the top zone): the rank
  double share = 0;  ///< the zone's share of the whole map's saliency, in (0, 1]
};

/// Spectral residual saliency map and its zones of interest. Immutable after construction:
/// thread-safe (every method is const and keeps no state).
class SpectralResidualSaliency {
 public:
  struct Options {
    /// Width of the working image the spectrum is computed on, px: kWorkingWidths (Hou &
    /// Zhang use 64). Its height follows the input's aspect ratio (at least 1 px).
    int working_width = 64;
    /// Standard deviation of the Gaussian that smooths the squared reconstruction, in working
    /// pixels: kBlurSigmas (0: no smoothing). 2.5 is Hou's published code at 64 px.
    double blur_sigma = 2.5;
    /// At most this many zones are returned: kMaxZones.
    int max_zones = 5;
    /// A working pixel belongs to a zone when its saliency exceeds zone_threshold times the
    /// map's mean: kZoneThresholds (Hou & Zhang: 3).
    double zone_threshold = 3.0;

    // The valid values, stated once (for IsValid and for a component's parameter ranges).
    static constexpr Interval kWorkingWidths = Interval::Closed(8, 1024);
    static constexpr Interval kBlurSigmas = Interval::Closed(0, 64);
    static constexpr Interval kMaxZones = Interval::Closed(1, 1000);
    static constexpr Interval kZoneThresholds = Interval::LeftOpen(0, 1000);

    /// Whether every field is in its range; if not, `error` (when not null) names the first
    /// field out of range, its value and the range expected.
    bool IsValid(std::string* error) const;
  };

  /// A working image whose 4-neighbour Laplacian stays below this (grey levels 0..255 per
  /// working pixel squared) at every pixel off its border has no salient structure: its map is
  /// all zeros and it has no zone. Shading with 8-bit rounding stays below 1.5 (a ramp 0.2, a
  /// vignette that darkens by 100 levels 1.4); a 20 px square 10 levels brighter than its
  /// surround in a 640 px image reaches 20.
  static constexpr double kFlatLaplacian = 2.0;

  SpectralResidualSaliency();  ///< default Options
  /// Throws InvalidArgument with IsValid's message.
  explicit SpectralResidualSaliency(const Options& options);

  /// The saliency map of an rgb8, rgba8 or gray8 image: CV_32FC1 of the image's size, values
  /// in [0, 1] (1 at the most salient pixel, all 0 for an image with no contrast). Throws
  /// InvalidArgument for another format or an empty image (a wiring error).
  cv::Mat Map(const Image& image) const;

  /// The zones of interest of an rgb8, rgba8 or gray8 image, highest peak first: at most
  /// max_zones, their boxes pairwise disjoint (a zone whose box overlaps a better zone's box
  /// is dropped), none for an image with no contrast. Throws as Map does.
  std::vector<SaliencyZone> Zones(const Image& image) const;

  /// Both at once (one spectrum).
  struct Result {
    cv::Mat map;                      ///< as Map returns
    std::vector<SaliencyZone> zones;  ///< as Zones returns
  };
  /// The map and the zones of one image, computing the spectrum once. Throws as Map does.
  Result Compute(const Image& image) const;

  const Options& options() const { return options_; }

 private:
  cv::Mat WorkingMap(const Image& image, const char* who) const;
  std::vector<SaliencyZone> ZonesOf(const cv::Mat& working_map, cv::Size image_size) const;

  Options options_;
};

}  // namespace saccade::vision
