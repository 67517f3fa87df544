#include "saccade/vision/saliency.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "saccade/core/error.h"
#include "vision/internal_cv.h"

namespace saccade::vision {

bool SpectralResidualSaliency::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kWorkingWidths.Contains(working_width)) {
    what = kWorkingWidths.Refusal("working_width", working_width);
  } else if (!kBlurSigmas.Contains(blur_sigma)) {
    what = kBlurSigmas.Refusal("blur_sigma", blur_sigma);
  } else if (!kMaxZones.Contains(max_zones)) {
    what = kMaxZones.Refusal("max_zones", max_zones);
  } else if (!kZoneThresholds.Contains(zone_threshold)) {
    what = kZoneThresholds.Refusal("zone_threshold", zone_threshold);
  }
  if (what.empty()) return true;
  if (error) *error = "SpectralResidualSaliency::Options: " + what;
  return false;
}

SpectralResidualSaliency::SpectralResidualSaliency() : SpectralResidualSaliency(Options()) {}

SpectralResidualSaliency::SpectralResidualSaliency(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
}

namespace {

// The spectrum of the smooth component s of Moisan's periodic plus smooth decomposition u = p + s
// (L. Moisan, "Periodic plus smooth image decomposition", J. Math. Imaging Vis. 39, 2011):
// s carries the jumps between opposite borders that the DFT's periodic extension sees, so that
// the spectrum of p = u - s has no wrap-around edge.
cv::Mat SmoothComponentSpectrum(const cv::Mat& u) {
  const int rows = u.rows, cols = u.cols;
  cv::Mat v = cv::Mat::zeros(rows, cols, CV_32F);
  for (int x = 0; x < cols; ++x) {
    const float jump = u.at<float>(rows - 1, x) - u.at<float>(0, x);
    v.at<float>(0, x) += jump;
    v.at<float>(rows - 1, x) -= jump;
  }
  for (int y = 0; y < rows; ++y) {
    const float jump = u.at<float>(y, cols - 1) - u.at<float>(y, 0);
    v.at<float>(y, 0) += jump;
    v.at<float>(y, cols - 1) -= jump;
  }
  cv::Mat spectrum;
  cv::dft(v, spectrum, cv::DFT_COMPLEX_OUTPUT);
  for (int r = 0; r < rows; ++r) {
    const double cy = 2.0 * std::cos(2.0 * CV_PI * r / rows);
    cv::Vec2f* row = spectrum.ptr<cv::Vec2f>(r);
    for (int q = 0; q < cols; ++q) {
      const double denominator = cy + 2.0 * std::cos(2.0 * CV_PI * q / cols) - 4.0;
      row[q] =
          (r == 0 && q == 0) ? cv::Vec2f(0, 0) : row[q] * static_cast<float>(1.0 / denominator);
    }
  }
  return spectrum;
}

// Whether |Laplacian| < limit at every pixel of `image` off its border (a border pixel's
// Laplacian depends on how the border is extended, not on the image).
bool IsFlat(const cv::Mat& image, double limit) {
  if (image.rows < 3 || image.cols < 3) {
    double lo = 0, hi = 0;
    cv::minMaxLoc(image, &lo, &hi);
    return hi - lo < limit;
  }
  cv::Mat laplacian;
  cv::Laplacian(image, laplacian, CV_32F, 1);
  double lo = 0, hi = 0;
  cv::minMaxLoc(laplacian(cv::Rect(1, 1, image.cols - 2, image.rows - 2)), &lo, &hi);
  return std::max(-lo, hi) < limit;
}

}  // namespace

cv::Mat SpectralResidualSaliency::WorkingMap(const Image& image, const char* who) const {
  const cv::Mat gray = internal::ToGray(image, who);
  const int width = options_.working_width;
  const int height = std::max(1, static_cast<int>(std::lround(static_cast<double>(image.height()) *
                                                              width / image.width())));
  // Float before the area average, so that a smooth gradient is not quantised into steps.
  cv::Mat gray_f;
  gray.convertTo(gray_f, CV_32F);
  cv::Mat small;
  cv::resize(gray_f, small, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  if (IsFlat(small, kFlatLaplacian)) return cv::Mat::zeros(height, width, CV_32F);
  small /= 255.0;
  // Hou & Zhang eq. 5-7: log amplitude and phase of the spectrum.
  cv::Mat spectrum;
  cv::dft(small, spectrum, cv::DFT_COMPLEX_OUTPUT);
  spectrum -= SmoothComponentSpectrum(small);  // no wrap-around edge (see the header)
  cv::Mat planes[2];
  cv::split(spectrum, planes);
  cv::Mat amplitude, phase;
  cv::cartToPolar(planes[0], planes[1], amplitude, phase);
  cv::Mat log_amplitude;
  // The amplitude of 8-bit rounding noise (uniform, 1 / (255 sqrt(12)) per pixel) at every
  // frequency: below it the spectrum says nothing, and synthetic images' exact zeros (log 0)
  // would rule the residual.
  const double noise_floor = std::sqrt(static_cast<double>(small.total()) / 12.0) / 255.0;
  cv::log(amplitude + noise_floor, log_amplitude);
  // Eq. 8: the residual is what the local average of the log spectrum does not explain.
  cv::Mat average;
  cv::blur(log_amplitude, average, cv::Size(3, 3), cv::Point(-1, -1), cv::BORDER_REPLICATE);
  cv::Mat residual;
  cv::exp(log_amplitude - average, residual);
  // Eq. 9: back to the image with the original phase; the squared magnitude, smoothed.
  cv::polarToCart(residual, phase, planes[0], planes[1]);
  cv::merge(planes, 2, spectrum);
  cv::Mat reconstruction;
  cv::dft(spectrum, reconstruction, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_COMPLEX_OUTPUT);
  cv::split(reconstruction, planes);
  cv::Mat map;
  cv::magnitude(planes[0], planes[1], map);
  map = map.mul(map);
  if (options_.blur_sigma > 0) {
    cv::GaussianBlur(map, map, cv::Size(0, 0), options_.blur_sigma, options_.blur_sigma,
                     cv::BORDER_REPLICATE);
  }
  double lo = 0, hi = 0;
  cv::minMaxLoc(map, &lo, &hi);
  if (!(hi > lo) || !std::isfinite(hi - lo)) return cv::Mat::zeros(height, width, CV_32F);
  map = (map - lo) / (hi - lo);
  return map;
}

std::vector<SaliencyZone> SpectralResidualSaliency::ZonesOf(const cv::Mat& working_map,
                                                            cv::Size image_size) const {
  const double total = cv::sum(working_map)[0];
  if (!(total > 0)) return {};
  const double threshold = options_.zone_threshold * total / working_map.total();
  const cv::Mat above = working_map > threshold;
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(above, labels, stats, centroids, 8, CV_32S);
  if (count <= 1) return {};  // label 0 is the background

  // Each region's saliency and its peak, in one pass.
  struct Region {
    int label = 0;
    double sum = 0;
    float peak_value = -1;
    cv::Point peak;
  };
  std::vector<Region> regions(count);
  for (int y = 0; y < working_map.rows; ++y) {
    const float* s = working_map.ptr<float>(y);
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < working_map.cols; ++x) {
      if (l[x] == 0) continue;
      Region& r = regions[l[x]];
      r.sum += s[x];
      if (s[x] > r.peak_value) {
        r.peak_value = s[x];
        r.peak = {x, y};
      }
    }
  }
  for (int i = 0; i < count; ++i) regions[i].label = i;
  regions.erase(regions.begin());
  std::sort(regions.begin(), regions.end(),
            [](const Region& a, const Region& b) { return a.peak_value > b.peak_value; });

  // Working pixel i covers the image pixels whose centres are nearest to its centre: j with
  // i <= (j + 0.5) / scale < i + 1. Disjoint working ranges give disjoint image ranges.
  const double sx = static_cast<double>(image_size.width) / working_map.cols;
  const double sy = static_cast<double>(image_size.height) / working_map.rows;
  const auto first_x = [&](int i) {
    return std::clamp(static_cast<int>(std::ceil(i * sx - 0.5)), 0, image_size.width);
  };
  const auto first_y = [&](int i) {
    return std::clamp(static_cast<int>(std::ceil(i * sy - 0.5)), 0, image_size.height);
  };
  std::vector<SaliencyZone> zones;
  std::vector<cv::Rect> taken;  // working-pixel boxes of the zones kept
  for (const Region& r : regions) {
    if (static_cast<int>(zones.size()) >= options_.max_zones) break;
    const cv::Rect box(
        stats.at<int>(r.label, cv::CC_STAT_LEFT), stats.at<int>(r.label, cv::CC_STAT_TOP),
        stats.at<int>(r.label, cv::CC_STAT_WIDTH), stats.at<int>(r.label, cv::CC_STAT_HEIGHT));
    if (std::any_of(taken.begin(), taken.end(),
                    [&](const cv::Rect& t) { return (t & box).area() > 0; })) {
      continue;
    }
    taken.push_back(box);
    SaliencyZone zone;
    const int x0 = first_x(box.x), x1 = first_x(box.x + box.width);
    const int y0 = first_y(box.y), y1 = first_y(box.y + box.height);
    zone.box = cv::Rect(x0, y0, std::max(1, x1 - x0), std::max(1, y1 - y0)) &
               cv::Rect(0, 0, image_size.width, image_size.height);
    const int px = static_cast<int>(std::lround((r.peak.x + 0.5) * sx - 0.5));
    const int py = static_cast<int>(std::lround((r.peak.y + 0.5) * sy - 0.5));
    zone.peak = {std::clamp(px, zone.box.x, zone.box.x + zone.box.width - 1),
                 std::clamp(py, zone.box.y, zone.box.y + zone.box.height - 1)};
    zone.score = r.peak_value;
    zone.share = r.sum / total;
    zones.push_back(zone);
  }
  return zones;
}

cv::Mat SpectralResidualSaliency::Map(const Image& image) const {
  const cv::Mat working = WorkingMap(image, "SpectralResidualSaliency::Map");
  cv::Mat map;
  cv::resize(working, map, cv::Size(image.width(), image.height()), 0, 0, cv::INTER_LINEAR);
  return map;
}

std::vector<SaliencyZone> SpectralResidualSaliency::Zones(const Image& image) const {
  const cv::Mat working = WorkingMap(image, "SpectralResidualSaliency::Zones");
  return ZonesOf(working, cv::Size(image.width(), image.height()));
}

SpectralResidualSaliency::Result SpectralResidualSaliency::Compute(const Image& image) const {
  const cv::Mat working = WorkingMap(image, "SpectralResidualSaliency::Compute");
  Result result;
  cv::resize(working, result.map, cv::Size(image.width(), image.height()), 0, 0, cv::INTER_LINEAR);
  result.zones = ZonesOf(working, cv::Size(image.width(), image.height()));
  return result;
}

}  // namespace saccade::vision
