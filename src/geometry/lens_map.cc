#include "saccade/geometry/lens_map.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::geometry {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The six cube faces in the fixed order of LensMap::views: +z, -z, +x, -x, +y, -y of C. Each
// R_CV has the columns x_V, y_V, z_V expressed in C, with z_V the face's axis and x_V x y_V =
// z_V. The side faces (+-x, and -z) keep y_V = +y_C (image "down" stays down, as in a panorama,
// i.e. the camera panned by +-90 or 180 degrees); the +y face is the camera tilted down by 90
// degrees (its image top looks forward, y_V = -z_C) and the -y face tilted up (y_V = +z_C).
Eigen::Matrix3d FaceRotation(int face) {
  Eigen::Matrix3d R;
  switch (face) {
    case 0:  // +z: the camera itself
      R << 1, 0, 0, 0, 1, 0, 0, 0, 1;
      break;
    case 1:  // -z: x_V = -x_C, y_V = y_C, z_V = -z_C
      R << -1, 0, 0, 0, 1, 0, 0, 0, -1;
      break;
    case 2:  // +x: x_V = -z_C, y_V = y_C, z_V = x_C
      R << 0, 0, 1, 0, 1, 0, -1, 0, 0;
      break;
    case 3:  // -x: x_V = z_C, y_V = y_C, z_V = -x_C
      R << 0, 0, -1, 0, 1, 0, 1, 0, 0;
      break;
    case 4:  // +y: x_V = x_C, y_V = -z_C, z_V = y_C
      R << 1, 0, 0, 0, 0, 1, 0, -1, 0;
      break;
    default:  // -y: x_V = x_C, y_V = z_C, z_V = -y_C
      R << 1, 0, 0, 0, 0, -1, 0, 1, 0;
      break;
  }
  return R;
}

// The cube face of a ray: the axis with the largest component (ties go to z, then x: a fixed
// rule, so that the map is deterministic), on the side of the component's sign.
int FaceOf(const Eigen::Vector3d& ray) {
  const double ax = std::abs(ray.x()), ay = std::abs(ray.y()), az = std::abs(ray.z());
  if (az >= ax && az >= ay) return ray.z() >= 0.0 ? 0 : 1;
  if (ax >= ay) return ray.x() >= 0.0 ? 2 : 3;
  return ray.y() >= 0.0 ? 4 : 5;
}

// A pinhole view at unit scale: q = A * (X_V / Z_V, Y_V / Z_V) with p_V = R_VC p_C and
// A = [a00 a01; 0 a11]. The view's source pixel is scale * q + c (c the principal point):
// kPinhole uses A = the camera's [fx skew; 0 fy] and scale s; a cube face uses A = I and
// scale f.
struct Projector {
  Eigen::Matrix3d R_VC = Eigen::Matrix3d::Identity();
  double a00 = 1.0, a01 = 0.0, a11 = 1.0;

  // False when the ray does not lie strictly in front of the view.
  bool Project(const Eigen::Vector3d& ray_C, Eigen::Vector2d* q) const {
    const Eigen::Vector3d p = R_VC * ray_C;
    if (!(p.z() > 0.0)) return false;
    const double inv_z = 1.0 / p.z();
    const double x = p.x() * inv_z, y = p.y() * inv_z;
    *q = Eigen::Vector2d(a00 * x + a01 * y, a11 * y);
    return true;
  }
};

// Smallest and largest singular values of the 2x2 matrix [a b; c d] (closed form).
void SingularValues(double a, double b, double c, double d, double* smallest, double* largest) {
  const double e = 0.5 * (a + d), f = 0.5 * (a - d), g = 0.5 * (c + b), h = 0.5 * (c - b);
  const double q = std::sqrt(e * e + h * h), r = std::sqrt(f * f + g * g);  // no overflow here
  *largest = q + r;
  *smallest = std::abs(q - r);
}

// Per-pixel inputs shared by the passes: the unit ray of every pixel and its view (-1: none).
struct Rays {
  int width = 0;
  int height = 0;
  std::vector<Eigen::Vector3d> ray;
  std::vector<int8_t> view;
};

struct Stats {
  double min_sigma = kInf;  // over pixels with a Jacobian; unit scale
  double max_sigma = 0.0;
  bool any = false;
  Eigen::Vector2d q_min = Eigen::Vector2d::Constant(kInf);  // bounding box of q (unit scale)
  Eigen::Vector2d q_max = Eigen::Vector2d::Constant(-kInf);
};

// The Jacobian d(q)/d(pixel) of every valid pixel, by central differences of its neighbours'
// rays projected into the pixel's own view (one-sided on the image border or next to a pixel
// with no ray; a pixel with no valid neighbour in u or in v has none), and the bounding box of
// q. Neighbours across a cube edge are projected into this pixel's face too, so that the
// difference measures the lens, not the face change.
Stats Measure(const Rays& rays, const std::vector<Projector>& projectors) {
  Stats stats;
  const int W = rays.width, H = rays.height;
  auto neighbour = [&](const Projector& P, int u, int v, Eigen::Vector2d* q) {
    if (u < 0 || u >= W || v < 0 || v >= H) return false;
    const std::size_t j = static_cast<std::size_t>(v) * W + u;
    return rays.view[j] >= 0 && P.Project(rays.ray[j], q);
  };
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * W + u;
      if (rays.view[i] < 0) continue;
      const Projector& P = projectors[rays.view[i]];
      Eigen::Vector2d q;
      if (!P.Project(rays.ray[i], &q)) continue;  // cannot happen: the view was chosen for it
      stats.q_min = stats.q_min.cwiseMin(q);
      stats.q_max = stats.q_max.cwiseMax(q);

      Eigen::Vector2d columns[2];
      bool have[2];
      for (int axis = 0; axis < 2; ++axis) {
        const int du = axis == 0 ? 1 : 0, dv = 1 - du;
        Eigen::Vector2d plus, minus;
        const bool has_plus = neighbour(P, u + du, v + dv, &plus);
        const bool has_minus = neighbour(P, u - du, v - dv, &minus);
        have[axis] = true;
        if (has_plus && has_minus) {
          columns[axis] = 0.5 * (plus - minus);
        } else if (has_plus) {
          columns[axis] = plus - q;
        } else if (has_minus) {
          columns[axis] = q - minus;
        } else {
          have[axis] = false;
        }
      }
      if (!have[0] || !have[1]) continue;
      double smallest, largest;
      SingularValues(columns[0].x(), columns[1].x(), columns[0].y(), columns[1].y(), &smallest,
                     &largest);
      stats.min_sigma = std::min(stats.min_sigma, smallest);
      stats.max_sigma = std::max(stats.max_sigma, largest);
      stats.any = true;
    }
  }
  return stats;
}

// Writes (scale * q + c, view) for every valid pixel, (0, 0, -1) elsewhere.
void WriteMap(const Rays& rays, const std::vector<Projector>& projectors,
              const std::vector<int>& compact_view, double scale,
              const std::vector<Eigen::Vector2d>& principal, LensMap* lens) {
  const std::size_t n = rays.ray.size();
  lens->map.assign(3 * n, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    float* out = &lens->map[3 * i];
    Eigen::Vector2d q;
    if (rays.view[i] < 0 || !projectors[rays.view[i]].Project(rays.ray[i], &q)) {
      out[2] = -1.0f;
      continue;
    }
    const int k = compact_view[rays.view[i]];
    const Eigen::Vector2d x = scale * q + principal[k];
    out[0] = static_cast<float>(x.x());
    out[1] = static_cast<float>(x.y());
    out[2] = static_cast<float>(k);
  }
}

LensMap IdentityMap(const CameraModel& camera) {
  const Intrinsics& K = camera.intrinsics();
  LensMap lens;
  lens.kind = LensMap::Kind::kIdentity;
  lens.width = K.width();
  lens.height = K.height();
  lens.views.push_back(SourceView{Eigen::Matrix3d::Identity(), K});
  lens.map.resize(3 * static_cast<std::size_t>(K.width()) * K.height());
  for (int v = 0; v < K.height(); ++v) {
    for (int u = 0; u < K.width(); ++u) {
      float* out = &lens.map[3 * (static_cast<std::size_t>(v) * K.width() + u)];
      out[0] = static_cast<float>(u);
      out[1] = static_cast<float>(v);
      out[2] = 0.0f;
    }
  }
  // The angle to the axis grows with the distance from the principal point in normalized
  // coordinates, so its largest value over the image is on the border.
  auto angle = [&](int u, int v) {
    const Eigen::Vector2d x = K.PixelToNormalized(Eigen::Vector2d(u, v));
    return std::atan2(x.norm(), 1.0);
  };
  for (int u = 0; u < K.width(); ++u) {
    lens.max_angle = std::max({lens.max_angle, angle(u, 0), angle(u, K.height() - 1)});
  }
  for (int v = 0; v < K.height(); ++v) {
    lens.max_angle = std::max({lens.max_angle, angle(0, v), angle(K.width() - 1, v)});
  }
  lens.min_scale = lens.max_scale = 1.0;
  return lens;
}

// The single wider pinhole view, or nothing when it would exceed max_source_side.
bool TryPinhole(const CameraModel& camera, const LensMapOptions& options, const Rays& rays,
                LensMap* lens) {
  const Intrinsics& K = camera.intrinsics();
  Projector P;
  P.a00 = K.fx();
  P.a01 = K.skew();
  P.a11 = K.fy();
  const std::vector<Projector> projectors = {P};
  const Stats stats = Measure(rays, projectors);

  // s: the smallest pitch that magnifies the source nowhere, within [1, max_supersampling].
  // (A zero singular value, a pixel whose neighbours share its source point, asks for the cap.)
  double s = 1.0;
  if (stats.any) s = stats.min_sigma > 0.0 ? 1.0 / stats.min_sigma : kInf;
  s = std::clamp(s, 1.0, options.max_supersampling);

  // Bounding box of the source points plus the margin: a point x must satisfy
  // -0.5 + margin <= x <= side - 0.5 - margin; the slack of rounding the side up to an integer
  // is split evenly between both ends.
  const Eigen::Vector2d extent = s * (stats.q_max - stats.q_min);
  const double margin = options.margin_px;
  const double width_d = std::ceil(extent.x() + 2.0 * margin);
  const double height_d = std::ceil(extent.y() + 2.0 * margin);
  if (!(width_d <= options.max_source_side && height_d <= options.max_source_side)) return false;
  const Eigen::Vector2d side(width_d, height_d);
  const Eigen::Vector2d slack = side - extent - Eigen::Vector2d::Constant(2.0 * margin);
  const Eigen::Vector2d c = Eigen::Vector2d::Constant(margin - 0.5) - s * stats.q_min + 0.5 * slack;

  lens->kind = LensMap::Kind::kPinhole;
  lens->views = {SourceView{Eigen::Matrix3d::Identity(),
                            Intrinsics(static_cast<int>(width_d), static_cast<int>(height_d),
                                       s * K.fx(), s * K.fy(), c.x(), c.y(), s * K.skew())}};
  lens->min_scale = stats.any ? s * stats.min_sigma : 0.0;
  lens->max_scale = stats.any ? s * stats.max_sigma : 0.0;
  WriteMap(rays, projectors, {0}, s, {c}, lens);
  return true;
}

void MakeCube(const CameraModel& camera, const LensMapOptions& options, Rays* rays, LensMap* lens) {
  const Intrinsics& K = camera.intrinsics();
  std::vector<Projector> projectors(6);
  for (int face = 0; face < 6; ++face) projectors[face].R_VC = FaceRotation(face).transpose();
  std::array<bool, 6> used{};
  for (std::size_t i = 0; i < rays->ray.size(); ++i) {
    if (rays->view[i] < 0) continue;
    const int face = FaceOf(rays->ray[i]);
    rays->view[i] = static_cast<int8_t>(face);
    used[face] = true;
  }
  const Stats stats = Measure(*rays, projectors);

  // Face size S (odd or even), principal point c = (S - 1) / 2 on both axes and focal
  //   f = (S - 1) / 2 - margin,
  // so that the face's 90-degree edges (normalized coordinate +-1) fall on c -+ f = margin and
  // S - 1 - margin: margin_px pixels inside the outermost pixel centres. S is the smallest
  // integer with f >= f_needed = 1 / (smallest singular value of d(q)/d(pixel)) (no output
  // pixel magnifies the source), then lowered to keep f <= max_supersampling * max(fx, fy)
  // and S <= max_source_side, and at least 2 margin + 2 (f >= 1/2).
  const double margin = options.margin_px;
  double f_needed = std::max(K.fx(), K.fy());  // no pixel with a Jacobian: the camera's own
  if (stats.any) f_needed = stats.min_sigma > 0.0 ? 1.0 / stats.min_sigma : kInf;
  const double f_cap = options.max_supersampling * std::max(K.fx(), K.fy());
  double side = std::ceil(2.0 * (f_needed + margin) + 1.0);
  side = std::min(side, std::floor(2.0 * (f_cap + margin) + 1.0));
  side = std::min(side, static_cast<double>(options.max_source_side));
  side = std::max(side, 2.0 * margin + 2.0);
  const int S = static_cast<int>(side);
  const double c = 0.5 * (S - 1);
  const double f = c - margin;

  lens->kind = LensMap::Kind::kCube;
  lens->views.clear();
  std::vector<int> compact_view(6, -1);
  std::vector<Eigen::Vector2d> principal;
  for (int face = 0; face < 6; ++face) {
    if (!used[face]) continue;
    compact_view[face] = static_cast<int>(lens->views.size());
    lens->views.push_back(SourceView{FaceRotation(face), Intrinsics(S, S, f, f, c, c)});
    principal.emplace_back(c, c);
  }
  lens->min_scale = stats.any ? f * stats.min_sigma : 0.0;
  lens->max_scale = stats.any ? f * stats.max_sigma : 0.0;
  WriteMap(*rays, projectors, compact_view, f, principal, lens);
}

}  // namespace

bool LensMapOptions::IsValid(std::string* error) const {
  std::string message;
  if (!(max_pinhole_angle > 0.0 && max_pinhole_angle < 0.5 * std::numbers::pi)) {
    message =
        fmt::format("max_pinhole_angle must be in (0, pi/2) radians, got {}", max_pinhole_angle);
  } else if (!(max_supersampling >= 1.0 && std::isfinite(max_supersampling))) {
    message =
        fmt::format("max_supersampling must be a finite number >= 1, got {}", max_supersampling);
  } else if (max_source_side < 16) {
    message = fmt::format("max_source_side must be >= 16 pixels, got {}", max_source_side);
  } else if (margin_px < 1) {
    message = fmt::format("margin_px must be >= 1 pixel, got {}", margin_px);
  } else if (margin_px > max_source_side / 4) {
    message = fmt::format(
        "margin_px must be at most max_source_side / 4 = {} pixels (the margins may take at most "
        "half of a cube face), got {}",
        max_source_side / 4, margin_px);
  }
  if (message.empty()) return true;
  if (error != nullptr) *error = std::move(message);
  return false;
}

LensMap MakeLensMap(const CameraModel& camera, const LensMapOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument("MakeLensMap: " + error);
  if (camera.distortion().IsIdentity()) return IdentityMap(camera);

  const Intrinsics& K = camera.intrinsics();
  const bool fisheye = camera.distortion().model() == DistortionModel::kFisheye;
  Rays rays;
  rays.width = K.width();
  rays.height = K.height();
  const std::size_t n = static_cast<std::size_t>(K.width()) * K.height();
  rays.ray.resize(n);
  rays.view.assign(n, -1);

  LensMap lens;
  lens.width = K.width();
  lens.height = K.height();
  // The valid ray with the smallest z (all are unit vectors) is the one farthest from the axis.
  std::size_t widest = n;
  for (int v = 0; v < K.height(); ++v) {
    for (int u = 0; u < K.width(); ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * K.width() + u;
      const std::optional<Eigen::Vector3d> ray = camera.Unproject(Eigen::Vector2d(u, v));
      if (!ray || !ray->allFinite() || (!fisheye && !(ray->z() > 0.0))) {
        ++lens.invalid_pixels;
        continue;
      }
      rays.ray[i] = *ray;
      rays.view[i] = 0;
      if (widest == n || ray->z() < rays.ray[widest].z()) widest = i;
    }
  }
  if (widest == n) {
    throw InvalidArgument(fmt::format(
        "MakeLensMap: no pixel of the {} x {} image has a ray (the {} distortion cannot be "
        "inverted anywhere in the image; coefficients [{}])",
        K.width(), K.height(), ToString(camera.distortion().model()),
        fmt::join(camera.distortion().coefficients(), ", ")));
  }
  const Eigen::Vector3d& far = rays.ray[widest];
  lens.max_angle = std::atan2(std::hypot(far.x(), far.y()), far.z());

  if (lens.max_angle <= options.max_pinhole_angle && TryPinhole(camera, options, rays, &lens)) {
    return lens;
  }
  MakeCube(camera, options, &rays, &lens);
  return lens;
}

}  // namespace saccade::geometry
