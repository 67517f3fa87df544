#include "saccade/components/explore_attention.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "saccade/head/fixation.h"
#include "saccade/vision/image_camera.h"

namespace saccade::components {
namespace {

constexpr int kColumns = 180;  // 2 degrees of azimuth
constexpr int kRows = 90;      // 2 degrees of elevation
// Measured on explore_room (bench/baselines/explore-2core.md): 7 x 7 rays over 0.9 of the view
// reached 80 % where 5 x 5 over 0.8 reached 78 %.
constexpr int kNoveltyRays = 7;
constexpr double kNoveltySpan = 0.9;
constexpr double kNoveltyStart_m = 0.3;  // beyond the head's own body

}  // namespace

Eigen::Vector3d DirectionOf(double azimuth, double elevation) {
  return Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                         std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
}

Eigen::Vector2d EyeFieldOfView(const head::HeadModel& head) {
  const geometry::Intrinsics& in = head.camera(0).model.intrinsics();
  return Eigen::Vector2d(in.HorizontalFov(), in.VerticalFov());
}

std::vector<Eigen::Vector3d> ReachGrid(const head::HeadModel& head, const Eigen::Vector2d& step,
                                       double distance) {
  head::FixationSolver solver(head);
  std::vector<Eigen::Vector3d> out;
  const int columns = static_cast<int>(std::floor(M_PI / step.x()));
  const int rows = static_cast<int>(std::floor((M_PI / 2 - 0.05) / step.y()));
  for (int r = rows; r >= -rows; --r) {
    std::vector<Eigen::Vector3d> row;
    for (int c = -columns; c <= columns; ++c) {
      const double azimuth = c * step.x();
      if (std::abs(azimuth) > M_PI - 1e-9 && c > -columns) continue;  // +-pi once
      const Eigen::Vector3d p_W = head.X_WB() * (distance * DirectionOf(azimuth, r * step.y()));
      head::FixationOptions options;
      options.axis_tolerance = 1e-4;
      if (solver.Solve(p_W, options).reachable()) row.push_back(p_W);
    }
    if ((rows - r) % 2 == 1) std::reverse(row.begin(), row.end());
    out.insert(out.end(), row.begin(), row.end());
  }
  return out;
}

ExploreAttention::ExploreAttention(const head::HeadModel& head, std::vector<Eigen::Vector3d> grid_W,
                                   const Options& options)
    : head_(head),
      grid_W_(std::move(grid_W)),
      options_(options),
      fov_(EyeFieldOfView(head)),
      looks_(kColumns * kRows, 0) {
  if (options.second_stage_faces) faces_ = std::make_unique<vision::FaceDetector>();
}

Eigen::Vector3d ExploreAttention::InBase(const Eigen::Vector3d& p_W) const {
  return head_.X_WB().inverse() * p_W;
}

// Calls f with the index of every 2-degree cell of the field of view `fov` about direction_B.
template <typename F>
void ExploreAttention::ForEachCell(const Eigen::Vector3d& direction_B, const Eigen::Vector2d& fov,
                                   F&& f) const {
  const double azimuth = std::atan2(direction_B.y(), direction_B.x());
  const double elevation = std::asin(std::clamp(direction_B.normalized().z(), -1.0, 1.0));
  const double cell = M_PI / kRows;
  const int half_columns = static_cast<int>(std::round(fov.x() / 2 / cell));
  const int half_rows = static_cast<int>(std::round(fov.y() / 2 / cell));
  const int column0 = static_cast<int>(std::floor((azimuth + M_PI) / cell));
  const int row0 = static_cast<int>(std::floor((elevation + M_PI / 2) / cell));
  for (int r = row0 - half_rows; r <= row0 + half_rows; ++r) {
    if (r < 0 || r >= kRows) continue;
    for (int c = column0 - half_columns; c <= column0 + half_columns; ++c) {
      f(r * kColumns + ((c % kColumns) + kColumns) % kColumns);
    }
  }
}

int ExploreAttention::Looks(const Eigen::Vector3d& direction_B) const {
  int n = 0;
  ForEachCell(direction_B, Eigen::Vector2d::Zero(), [&](int index) { n = looks_[index]; });
  return n;
}

double RayNovelty(const mapping::WorldMap& map, const Eigen::Vector3d& origin_W,
                  const Eigen::Vector3d& direction_W, double max_range_m, int looks,
                  double tentative_value) {
  switch (map.FirstAlong(origin_W, direction_W, max_range_m)) {
    case mapping::RayEnd::kUnknown:
      return std::ldexp(1.0, -looks);
    case mapping::RayEnd::kTentative:  // halved for every look past the second
      return std::ldexp(tentative_value, -std::max(looks - 2, 0));
    case mapping::RayEnd::kOccupied:
    case mapping::RayEnd::kNothing:
      break;
  }
  return 0.0;
}

double ExploreAttention::Novelty(const Eigen::Vector3d& p_W, const mapping::WorldMap* map) const {
  const Eigen::Vector3d d_B = InBase(p_W).normalized();
  if (map == nullptr) {
    int cells = 0, fresh = 0;
    ForEachCell(d_B, fov_, [&](int index) {
      ++cells;
      fresh += looks_[index] == 0 ? 1 : 0;
    });
    return cells > 0 ? static_cast<double>(fresh) / cells : 0.0;
  }
  const double azimuth = std::atan2(d_B.y(), d_B.x());
  const double elevation = std::asin(std::clamp(d_B.z(), -1.0, 1.0));
  const Eigen::Vector3d origin_W = head_.X_WB().translation();
  double sum = 0.0;
  for (int i = 0; i < kNoveltyRays; ++i) {
    for (int j = 0; j < kNoveltyRays; ++j) {
      const double a = kNoveltySpan * (static_cast<double>(i) / (kNoveltyRays - 1) - 0.5);
      const double e = kNoveltySpan * (static_cast<double>(j) / (kNoveltyRays - 1) - 0.5);
      const Eigen::Vector3d r_B = DirectionOf(azimuth + a * fov_.x(), elevation + e * fov_.y());
      const Eigen::Vector3d r_W = head_.X_WB().linear() * r_B;
      sum += RayNovelty(*map, origin_W + kNoveltyStart_m * r_W, r_W, options_.max_range_m,
                        Looks(r_B), options_.tentative_value);
    }
  }
  return sum / (kNoveltyRays * kNoveltyRays);
}

void ExploreAttention::Looked(const Eigen::Vector3d& p_W) {
  gaze_B_ = InBase(p_W).normalized();
  ForEachCell(gaze_B_, fov_, [&](int index) {
    looks_[index] = static_cast<uint8_t>(std::min(looks_[index] + 1, 255));
  });
}

std::vector<ExploreCandidate> ExploreAttention::Rank(const vision::StereoDepth* depth,
                                                     const Image* left,
                                                     const Inhibition& inhibition,
                                                     const mapping::WorldMap* map) {
  std::vector<ExploreCandidate> out;
  const auto add = [&](const Eigen::Vector3d& p_W, double saliency,
                       ExploreCandidate::Source source) {
    const Eigen::Vector3d d = InBase(p_W).normalized();
    const double turn = std::acos(std::clamp(d.dot(gaze_B_), -1.0, 1.0));
    const double score = options_.saliency_weight * saliency +
                         options_.novelty_weight * Novelty(p_W, map) - inhibition(p_W) -
                         options_.turn_weight * turn;
    out.push_back({p_W, score, source});
  };
  if (depth != nullptr && left != nullptr) {
    const geometry::CameraModel camera = vision::CameraModelOf(*left);
    const geometry::Pose X_WC = vision::CameraPoseOf(*left);
    std::optional<std::pair<cv::Rect, double>> best_zone;
    for (const vision::SaliencyZone& zone : saliency_.Compute(*left).zones) {
      const std::optional<Eigen::Vector3d> ray =
          camera.Unproject(Eigen::Vector2d(zone.peak.x, zone.peak.y));
      if (!ray) continue;
      const Eigen::Vector3d ray_W = X_WC.linear() * ray->normalized();
      add(X_WC.translation() + DepthAlong(*depth, ray_W) * ray_W, zone.score,
          ExploreCandidate::Source::kSaliency);
      if (!best_zone || out.back().score > best_zone->second) {
        best_zone = {zone.box, out.back().score};
      }
    }
    if (faces_ && best_zone) FacesIn(best_zone->first, *left, *depth, best_zone->second, &out);
  }
  for (const Eigen::Vector3d& p : grid_W_) add(p, 0.0, ExploreCandidate::Source::kReach);
  std::stable_sort(
      out.begin(), out.end(),
      [](const ExploreCandidate& a, const ExploreCandidate& b) { return a.score > b.score; });
  return out;
}

void ExploreAttention::FacesIn(const cv::Rect& zone, const Image& left,
                               const vision::StereoDepth& depth, double zone_score,
                               std::vector<ExploreCandidate>* out) {
  const cv::Rect grown(zone.x - zone.width / 2, zone.y - zone.height / 2, zone.width * 2,
                       zone.height * 2);
  const geometry::CameraModel camera = vision::CameraModelOf(left);
  const geometry::Pose X_WC = vision::CameraPoseOf(left);
  for (const vision::FaceDetection& face : faces_->Detect(left, {grown})) {
    if (face.rejected) continue;
    const std::optional<Eigen::Vector3d> ray = camera.Unproject(
        Eigen::Vector2d(face.box.x + face.box.width / 2.0, face.box.y + face.box.height / 2.0));
    if (!ray) continue;
    const Eigen::Vector3d ray_W = X_WC.linear() * ray->normalized();
    out->push_back({X_WC.translation() + DepthAlong(depth, ray_W) * ray_W,
                    zone_score + options_.face_weight, ExploreCandidate::Source::kFace});
  }
}

// The range (m) along a world ray from the camera's centre: the stereo depth where the ray
// meets the rectified view with a match, the target distance otherwise.
double ExploreAttention::DepthAlong(const vision::StereoDepth& depth,
                                    const Eigen::Vector3d& ray_W) const {
  const Eigen::Vector3d r_R = depth.X_WR.linear().transpose() * ray_W.normalized();
  if (r_R.z() > 0) {
    const Eigen::Vector3d uv = depth.rectified.Matrix() * (r_R / r_R.z());
    const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
    if (u >= 0 && v >= 0 && u < depth.depth.width() && v < depth.depth.height()) {
      const float z =
          reinterpret_cast<const float*>(depth.depth.data() + v * depth.depth.stride())[u];
      if (z > 0) return z / r_R.z();
    }
  }
  return options_.target_distance_m;
}

}  // namespace saccade::components
