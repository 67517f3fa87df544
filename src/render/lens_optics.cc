#include "saccade/render/lens_optics.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
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

// The sum of DofCoverage over the plane: pi (r^2 + 1/12) for r >= 0.5 (the ramp integrated);
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
// Pixels of a row gathered at once (one SSE vector of floats each term): a divisor of kDofTile.
constexpr int kDofLanes = 4;
using DofVector = float __attribute__((vector_size(kDofLanes * sizeof(float))));

// What the gather reads per pixel, in planes padded by the window's reach (pad_x, pad_y)
// around the image and kDofLanes more on the right, so that a run of kDofLanes pixels reads
// every offset without a bounds test: depth (+inf without a surface), the circle's radius
// (pixels across, capped) and area (DiscArea), whether the pixel is in the image (1 or 0:
// padding's terms weigh 0) and the colour's three channels. Also the window's offsets sorted
// by distance, and per tile the largest radius of any pixel within the window's reach of the
// tile (so that a pixel's gather stops where no disc, its own or a nearer pixel's, can cover
// it: the same terms, fewer visits).
struct DofPlanes {
  int width = 0, height = 0;
  int pad_x = 0, pad_y = 0, stride = 0;  // stride: padded plane's row, in values
  std::vector<float> depth, radius, area, inside, color[3];
  std::vector<WindowOffset> window;
  int tiles_x = 0;
  std::vector<float> reach;  // per tile: the largest radius near it, + 0.5
  // The index of image pixel (x, y) in the padded planes.
  std::size_t At(int x, int y) const {
    return static_cast<std::size_t>(y + pad_y) * stride + static_cast<std::size_t>(x + pad_x);
  }
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
      m = std::max(m, planes->radius[planes->At(x, y)]);
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

DofPlanes PrepareDof(const ImageView& rgb, const ImageView& depth, const ThinLensOptions& lens,
                     const geometry::Intrinsics& k, DepthOfFieldSummary* summary) {
  DofPlanes planes;
  planes.width = depth.width();
  planes.height = depth.height();
  std::vector<float> radius(static_cast<std::size_t>(planes.width) * planes.height);
  float max_radius = 0.0f;
  // CircleOfConfusionPx's terms, in its order, hoisted out of the loop.
  const double at_infinity = CircleOfConfusion(lens, 0.0);
  const double pitch = lens.pixel_pitch_m > 0.0 ? lens.pixel_pitch_m : lens.focal_length_m / k.fx();
  const double s = lens.focus_distance_m;
  for (int y = 0; y < planes.height; ++y) {
    const float* row = reinterpret_cast<const float*>(depth.row(y));
    for (int x = 0; x < planes.width; ++x) {
      const float d = row[x];
      const bool surface = std::isfinite(d) && d > 0.0f;
      const double coc = (surface ? at_infinity * std::abs(d - s) / d : at_infinity) / pitch;
      summary->max_coc_px = std::max(summary->max_coc_px, coc);
      if (coc > lens.max_coc_px) ++summary->capped_pixels;
      const auto r = static_cast<float>(0.5 * std::min(coc, lens.max_coc_px));
      radius[static_cast<std::size_t>(y) * planes.width + x] = r;
      max_radius = std::max(max_radius, r);
    }
  }
  const double aspect = lens.pixel_pitch_m > 0.0 ? 1.0 : k.fx() / k.fy();  // pitch_y / pitch_x
  const int reach_x = static_cast<int>(std::ceil(max_radius + 0.5f));
  const int reach_y = static_cast<int>(std::ceil((max_radius + 0.5f) / aspect));
  planes.pad_x = reach_x;
  planes.pad_y = reach_y;
  planes.stride = planes.width + 2 * reach_x + kDofLanes;
  const std::size_t n = static_cast<std::size_t>(planes.stride) * (planes.height + 2 * reach_y);
  planes.depth.assign(n, std::numeric_limits<float>::infinity());  // padding: never in front
  planes.radius.assign(n, 0.0f);
  planes.area.assign(n, DiscArea(0.0f));
  planes.inside.assign(n, 0.0f);
  for (std::vector<float>& c : planes.color) c.assign(n, 0.0f);
  for (int y = 0; y < planes.height; ++y) {
    const float* row = reinterpret_cast<const float*>(depth.row(y));
    const uint8_t* c = rgb.row(y);
    for (int x = 0; x < planes.width; ++x) {
      const std::size_t i = planes.At(x, y);
      const float d = row[x];
      planes.depth[i] = std::isfinite(d) && d > 0.0f ? d : std::numeric_limits<float>::infinity();
      planes.radius[i] = radius[static_cast<std::size_t>(y) * planes.width + x];
      planes.area[i] = DiscArea(planes.radius[i]);
      planes.inside[i] = 1.0f;
      for (int ch = 0; ch < 3; ++ch) planes.color[ch][i] = c[3 * x + ch];
    }
  }
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

DofVector LoadDof(const float* values) {
  DofVector v;
  std::memcpy(&v, values, sizeof(v));
  return v;
}

// How much of a pixel at `distance` (pixels) a disc of radius `radius` covers, anti-aliased
// over one pixel: 1 inside radius - 0.5, 0 beyond radius + 0.5, linear between; for kDofLanes
// discs.
DofVector DofCoverage(float distance, DofVector radius) {
  DofVector c = radius + 0.5f - distance;
  c = c < 0.0f ? DofVector{} : c;
  return c > 1.0f ? DofVector{} + 1.0f : c;
}

// kDofLanes output pixels from (x, y) on of one tile's row (the header's gather of what is
// behind, scatter of what is in front), into out[0 .. count). The tile's reach bounds every
// pixel's own circle and those near it (the window is sorted by distance): beyond it every
// term is 0. Each term is the scalar gather's, in its order: the same bits as pixel by pixel.
void DofRun(const DofPlanes& planes, int x, int y, int count, uint8_t* out) {
  const std::size_t p = planes.At(x, y);
  const DofVector radius_p = LoadDof(&planes.radius[p]);
  const DofVector nearer = LoadDof(&planes.depth[p]) * (1.0f - kNearerFraction);
  DofVector back_weight{}, front_weight{}, back[3] = {}, front[3] = {};
  const float limit =
      planes.reach[static_cast<std::size_t>(y / kDofTile) * planes.tiles_x + x / kDofTile];
  const auto offset = [&](const WindowOffset& o) {
    return static_cast<std::ptrdiff_t>(o.dy) * planes.stride + o.dx;
  };
  for (const WindowOffset& o : planes.window) {
    if (o.distance >= limit) break;
    const std::size_t q = p + offset(o);
    const auto in_front = LoadDof(&planes.depth[q]) < nearer;
    // In front: q's disc over p, weighed by 1 / its area; else p's disc over q (inside only).
    const DofVector w_front =
        DofCoverage(o.distance, LoadDof(&planes.radius[q])) / LoadDof(&planes.area[q]);
    const DofVector w_back = DofCoverage(o.distance, radius_p) * LoadDof(&planes.inside[q]);
    const DofVector f = in_front ? w_front : DofVector{};
    const DofVector b = in_front ? DofVector{} : w_back;
    front_weight += f;
    back_weight += b;
    for (int ch = 0; ch < 3; ++ch) {
      const DofVector c = LoadDof(&planes.color[ch][q]);
      front[ch] += f * c;
      back[ch] += b * c;
    }
  }
  for (int j = 0; j < count; ++j) {
    const float alpha = std::min(1.0f, front_weight[j]);
    for (int ch = 0; ch < 3; ++ch) {
      float value = back_weight[j] > 0.0f ? back[ch][j] / back_weight[j] : 0.0f;
      if (front_weight[j] > 0.0f) {
        value = alpha * front[ch][j] / front_weight[j] + (1.0f - alpha) * value;
      }
      // lround of a value in [0, 255]: + 0.5 is exact in double, truncated (no libm call).
      out[3 * j + ch] =
          static_cast<uint8_t>(static_cast<double>(std::clamp(value, 0.0f, 255.0f)) + 0.5);
    }
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
  const DofPlanes planes = PrepareDof(rgb, depth, lens, intrinsics, out_summary);
  Image out(rgb.width(), rgb.height(), PixelFormat::kRgb8);
  if (rgb.metadata() != nullptr) out.metadata() = *rgb.metadata();
  const auto rows = [&](int first, int end) {
    for (int y = first; y < end; ++y) {
      uint8_t* row = out.row(y);
      for (int x = 0; x < rgb.width(); x += kDofLanes) {
        DofRun(planes, x, y, std::min(kDofLanes, rgb.width() - x), row + 3 * x);
      }
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
