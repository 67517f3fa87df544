#include "saccade/render/lens_optics.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::render {

namespace {

// A pixel nearer than the output pixel by more than this fraction of the output pixel's depth
// is in front of it (scattered over); closer ones belong to its surface (gathered). Above
// float depth's rounding, below any gap between objects that matters at the scale of a disc.
constexpr float kNearerFraction = 1e-3f;

void CheckLensPositive(double value, const char* field) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw InvalidArgument(fmt::format("{}: expected a finite number > 0, got {}", field, value));
  }
}

// How much of a pixel at `distance` (pixels) a disc of radius `radius` covers, anti-aliased
// over one pixel: 1 inside radius - 0.5, 0 beyond radius + 0.5, linear between.
float DiscCoverage(float distance, float radius) {
  return std::clamp(radius + 0.5f - distance, 0.0f, 1.0f);
}

// The sum of DiscCoverage over the plane: pi (r^2 + 1/12) for r >= 0.5 (the ramp integrated);
// below, the disc covers its own pixel only, by r + 0.5.
float DiscArea(float radius) {
  constexpr float kPi = std::numbers::pi_v<float>;
  return radius < 0.5f ? radius + 0.5f : kPi * (radius * radius + 1.0f / 12.0f);
}

// One offset of the gather's window, with its distance in pixels across (rows scaled by
// pitch_y / pitch_x, so that a disc on the sensor is a circle here).
struct WindowOffset {
  int dx, dy;
  float distance;
};

// Tiles of kDofTile x kDofTile pixels bound the circles a pixel's gather can meet.
constexpr int kDofTile = 16;

// What the gather reads per pixel: depth (+inf without a surface) and the circle's radius
// (pixels across, capped); the window's offsets sorted by distance, and per tile the largest
// radius of any pixel within the window's reach of the tile (so that a pixel's gather stops
// where no disc, its own or a nearer pixel's, can cover it: the same terms, fewer visits).
struct DofPlanes {
  int width = 0, height = 0;
  std::vector<float> depth;
  std::vector<float> radius;
  std::vector<WindowOffset> window;
  int tiles_x = 0;
  std::vector<float> reach;  // per tile: the largest radius near it, + 0.5
};

// DofPlanes::reach: each tile's largest radius, then the largest over the tiles the window
// reaches from it.
void PrepareTileReach(DofPlanes* planes, int reach_x, int reach_y) {
  const int tiles_x = (planes->width + kDofTile - 1) / kDofTile;
  const int tiles_y = (planes->height + kDofTile - 1) / kDofTile;
  std::vector<float> tile_max(static_cast<std::size_t>(tiles_x) * tiles_y, 0.0f);
  for (int y = 0; y < planes->height; ++y) {
    for (int x = 0; x < planes->width; ++x) {
      float& m = tile_max[static_cast<std::size_t>(y / kDofTile) * tiles_x + x / kDofTile];
      m = std::max(m, planes->radius[static_cast<std::size_t>(y) * planes->width + x]);
    }
  }
  const int tx_reach = (reach_x + kDofTile - 1) / kDofTile;
  const int ty_reach = (reach_y + kDofTile - 1) / kDofTile;
  planes->tiles_x = tiles_x;
  planes->reach.assign(tile_max.size(), 0.0f);
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      float m = 0.0f;
      for (int j = std::max(0, ty - ty_reach); j <= std::min(tiles_y - 1, ty + ty_reach); ++j) {
        for (int i = std::max(0, tx - tx_reach); i <= std::min(tiles_x - 1, tx + tx_reach); ++i) {
          m = std::max(m, tile_max[static_cast<std::size_t>(j) * tiles_x + i]);
        }
      }
      planes->reach[static_cast<std::size_t>(ty) * tiles_x + tx] = m + 0.5f;
    }
  }
}

DofPlanes PrepareDof(const ImageView& depth, const ThinLensOptions& lens,
                     const geometry::Intrinsics& k, DepthOfFieldSummary* summary) {
  DofPlanes planes;
  planes.width = depth.width();
  planes.height = depth.height();
  const std::size_t n = static_cast<std::size_t>(planes.width) * planes.height;
  planes.depth.resize(n);
  planes.radius.resize(n);
  float max_radius = 0.0f;
  for (int y = 0; y < planes.height; ++y) {
    const float* row = reinterpret_cast<const float*>(depth.row(y));
    for (int x = 0; x < planes.width; ++x) {
      const float d = row[x];
      const bool surface = std::isfinite(d) && d > 0.0f;
      const double coc = CircleOfConfusionPx(lens, k, surface ? d : 0.0);
      summary->max_coc_px = std::max(summary->max_coc_px, coc);
      if (coc > lens.max_coc_px) ++summary->capped_pixels;
      const std::size_t i = static_cast<std::size_t>(y) * planes.width + x;
      planes.depth[i] = surface ? d : std::numeric_limits<float>::infinity();
      planes.radius[i] = static_cast<float>(0.5 * std::min(coc, lens.max_coc_px));
      max_radius = std::max(max_radius, planes.radius[i]);
    }
  }
  const double aspect = lens.pixel_pitch_m > 0.0 ? 1.0 : k.fx() / k.fy();  // pitch_y / pitch_x
  const int reach_x = static_cast<int>(std::ceil(max_radius + 0.5f));
  const int reach_y = static_cast<int>(std::ceil((max_radius + 0.5f) / aspect));
  for (int dy = -reach_y; dy <= reach_y; ++dy) {
    for (int dx = -reach_x; dx <= reach_x; ++dx) {
      const auto distance = static_cast<float>(std::hypot(dx, dy * aspect));
      if (distance < max_radius + 0.5f) planes.window.push_back({dx, dy, distance});
    }
  }
  std::stable_sort(
      planes.window.begin(), planes.window.end(),
      [](const WindowOffset& a, const WindowOffset& b) { return a.distance < b.distance; });
  PrepareTileReach(&planes, reach_x, reach_y);
  return planes;
}

// One output pixel of ApplyDepthOfField (the header's gather of what is behind, scatter of
// what is in front).
void DofPixel(const ImageView& rgb, const DofPlanes& planes, int x, int y, uint8_t* out) {
  const std::size_t p = static_cast<std::size_t>(y) * planes.width + x;
  const float depth_p = planes.depth[p], radius_p = planes.radius[p];
  const float nearer = depth_p * (1.0f - kNearerFraction);
  float back_weight = 0.0f, front_weight = 0.0f;
  float back[3] = {0, 0, 0}, front[3] = {0, 0, 0};
  // No disc reaches p from this far (the window is sorted by distance): neither p's own nor
  // that of any pixel near p's tile.
  const float limit = std::max(
      radius_p + 0.5f,
      planes.reach[static_cast<std::size_t>(y / kDofTile) * planes.tiles_x + x / kDofTile]);
  for (const WindowOffset& o : planes.window) {
    if (o.distance >= limit) break;
    const int qx = x + o.dx, qy = y + o.dy;
    if (qx < 0 || qy < 0 || qx >= planes.width || qy >= planes.height) continue;
    const std::size_t q = static_cast<std::size_t>(qy) * planes.width + qx;
    const uint8_t* c = rgb.row(qy) + 3 * qx;
    if (planes.depth[q] < nearer) {
      const float coverage = DiscCoverage(o.distance, planes.radius[q]);
      if (coverage <= 0.0f) continue;
      const float w = coverage / DiscArea(planes.radius[q]);
      front_weight += w;
      for (int ch = 0; ch < 3; ++ch) front[ch] += w * c[ch];
    } else {
      const float coverage = DiscCoverage(o.distance, radius_p);
      if (coverage <= 0.0f) continue;
      back_weight += coverage;
      for (int ch = 0; ch < 3; ++ch) back[ch] += coverage * c[ch];
    }
  }
  const float alpha = std::min(1.0f, front_weight);
  for (int ch = 0; ch < 3; ++ch) {
    float value = back_weight > 0.0f ? back[ch] / back_weight : 0.0f;
    if (front_weight > 0.0f) value = alpha * front[ch] / front_weight + (1.0f - alpha) * value;
    out[ch] = static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 255.0f)));
  }
}

}  // namespace

const char* ToString(VignettingModel model) {
  switch (model) {
    case VignettingModel::kNone:
      return "none";
    case VignettingModel::kCos4:
      return "cos4";
    case VignettingModel::kPolynomial:
      return "polynomial";
  }
  return "unknown";
}

VignettingModel ParseVignettingModel(std::string_view text, std::string_view field) {
  std::string name(text);
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (VignettingModel m :
       {VignettingModel::kNone, VignettingModel::kCos4, VignettingModel::kPolynomial}) {
    if (name == ToString(m)) return m;
  }
  throw InvalidArgument(fmt::format(
      "{}: unknown vignetting model '{}', expected none, cos4 or polynomial", field, text));
}

double VignettingOptions::Polynomial(double r) const {
  if (model != VignettingModel::kPolynomial) return 1.0;
  const double r2 = r * r;
  return 1.0 + r2 * (coefficients[0] + r2 * (coefficients[1] + r2 * coefficients[2]));
}

void VignettingOptions::Validate() const {
  for (std::size_t i = 0; i < coefficients.size(); ++i) {
    if (!std::isfinite(coefficients[i])) {
      throw InvalidArgument(fmt::format(
          "vignetting.coefficients: a{} is {}, expected a finite number", i + 1, coefficients[i]));
    }
  }
  for (int i = 0; i <= 1000; ++i) {
    const double r = i / 1000.0;
    if (Polynomial(r) < 0.0) {
      throw InvalidArgument(fmt::format(
          "vignetting.coefficients: 1 + {} r^2 + {} r^4 + {} r^6 is {} at r = {}, expected a "
          "relative illumination >= 0 for r in [0, 1]",
          coefficients[0], coefficients[1], coefficients[2], Polynomial(r), r));
    }
  }
}

Image VignettingFactors(const geometry::CameraModel& camera, const VignettingOptions& options) {
  options.Validate();
  const geometry::Intrinsics& k = camera.intrinsics();
  Image factors(k.width(), k.height(), PixelFormat::kFloat32);
  double farthest = 0.0;  // principal point to the farthest corner of the image
  for (const double u : {-0.5, k.width() - 0.5}) {
    for (const double v : {-0.5, k.height() - 0.5}) {
      farthest = std::max(farthest, std::hypot(u - k.cx(), v - k.cy()));
    }
  }
  for (int y = 0; y < k.height(); ++y) {
    float* row = reinterpret_cast<float*>(factors.row(y));
    for (int x = 0; x < k.width(); ++x) {
      double factor = 1.0;
      if (options.model == VignettingModel::kCos4) {
        const std::optional<Eigen::Vector3d> ray = camera.Unproject(Eigen::Vector2d(x, y));
        const double cos_theta = ray ? std::max(0.0, ray->z() / ray->norm()) : 0.0;
        factor = std::pow(cos_theta, 4);
      } else if (options.model == VignettingModel::kPolynomial) {
        factor = options.Polynomial(std::hypot(x - k.cx(), y - k.cy()) / farthest);
      }
      row[x] = static_cast<float>(factor);
    }
  }
  return factors;
}

void ApplyVignetting(Image& rgb, const Image& factors) {
  if (rgb.format() != PixelFormat::kRgb8 || factors.format() != PixelFormat::kFloat32) {
    throw InvalidArgument(
        fmt::format("ApplyVignetting: formats {} and {}, expected rgb8 and float32 factors",
                    ToString(rgb.format()), ToString(factors.format())));
  }
  if (rgb.width() != factors.width() || rgb.height() != factors.height()) {
    throw InvalidArgument(
        fmt::format("ApplyVignetting: a {} x {} image with {} x {} factors, expected the same size",
                    rgb.width(), rgb.height(), factors.width(), factors.height()));
  }
  for (int y = 0; y < rgb.height(); ++y) {
    uint8_t* row = rgb.row(y);
    const float* f = reinterpret_cast<const float*>(factors.row(y));
    for (int x = 0; x < rgb.width(); ++x) {
      for (int ch = 0; ch < 3; ++ch) {
        const float value = std::clamp(row[3 * x + ch] * f[x], 0.0f, 255.0f);
        // lround of a value in [0, 255]: value + 0.5 is exact in double, its floor the
        // rounding half away from zero (and it vectorises).
        row[3 * x + ch] = static_cast<uint8_t>(static_cast<double>(value) + 0.5);
      }
    }
  }
}

void ThinLensOptions::Validate() const {
  CheckLensPositive(focal_length_m, "thin_lens.focal_length_m");
  CheckLensPositive(f_number, "thin_lens.f_number");
  if (!std::isfinite(focus_distance_m) || focus_distance_m <= focal_length_m) {
    throw InvalidArgument(fmt::format(
        "thin_lens.focus_distance_m: expected a finite distance beyond the focal length ({} m), "
        "got {}",
        focal_length_m, focus_distance_m));
  }
  if (!std::isfinite(pixel_pitch_m) || pixel_pitch_m < 0.0) {
    throw InvalidArgument(
        fmt::format("thin_lens.pixel_pitch_m: expected a finite number >= 0 (0: from K), got {}",
                    pixel_pitch_m));
  }
  if (!std::isfinite(max_coc_px) || max_coc_px < 1.0) {
    throw InvalidArgument(
        fmt::format("thin_lens.max_coc_px: expected a finite number >= 1, got {}", max_coc_px));
  }
}

double CircleOfConfusion(const ThinLensOptions& lens, double depth_m) {
  const double f = lens.focal_length_m, s = lens.focus_distance_m;
  const double aperture = f / lens.f_number;
  const double at_infinity = aperture * f / (s - f);
  if (!(depth_m > 0.0) || std::isinf(depth_m)) return at_infinity;
  return at_infinity * std::abs(depth_m - s) / depth_m;
}

double CircleOfConfusionPx(const ThinLensOptions& lens, const geometry::Intrinsics& intrinsics,
                           double depth_m) {
  const double pitch =
      lens.pixel_pitch_m > 0.0 ? lens.pixel_pitch_m : lens.focal_length_m / intrinsics.fx();
  return CircleOfConfusion(lens, depth_m) / pitch;
}

Image ApplyDepthOfField(const ImageView& rgb, const ImageView& depth, const ThinLensOptions& lens,
                        const geometry::Intrinsics& intrinsics, DepthOfFieldSummary* summary) {
  lens.Validate();
  if (rgb.format() != PixelFormat::kRgb8 || depth.format() != PixelFormat::kFloat32) {
    throw InvalidArgument(fmt::format(
        "ApplyDepthOfField: formats {} and {}, expected an rgb8 image and its float32 depth",
        ToString(rgb.format()), ToString(depth.format())));
  }
  if (rgb.width() != depth.width() || rgb.height() != depth.height()) {
    throw InvalidArgument(fmt::format(
        "ApplyDepthOfField: a {} x {} image with a {} x {} depth, expected the same size",
        rgb.width(), rgb.height(), depth.width(), depth.height()));
  }
  DepthOfFieldSummary local;
  DepthOfFieldSummary* out_summary = summary != nullptr ? summary : &local;
  *out_summary = {};
  const DofPlanes planes = PrepareDof(depth, lens, intrinsics, out_summary);
  Image out(rgb.width(), rgb.height(), PixelFormat::kRgb8);
  if (rgb.metadata() != nullptr) out.metadata() = *rgb.metadata();
  const auto rows = [&](int first, int end) {
    for (int y = first; y < end; ++y) {
      uint8_t* row = out.row(y);
      for (int x = 0; x < rgb.width(); ++x) DofPixel(rgb, planes, x, y, row + 3 * x);
    }
  };
  // Two halves at once where there are two cores (each pixel is computed alone: the same bits).
  static const bool cores = std::thread::hardware_concurrency() >= 2;  // asked once
  if (cores && rgb.height() >= 2 * kDofTile) {
    const int half = rgb.height() / 2;
    std::thread other(rows, half, rgb.height());
    rows(0, half);
    other.join();
  } else {
    rows(0, rgb.height());
  }
  return out;
}

}  // namespace saccade::render
