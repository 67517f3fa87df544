#include "saccade/mapping/map_score.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "saccade/core/error.h"

namespace saccade::mapping {

std::size_t PointGrid::KeyHash::operator()(const Eigen::Vector3i& k) const {
  const uint64_t h = (static_cast<uint64_t>(static_cast<uint32_t>(k.x())) * 73856093u) ^
                     (static_cast<uint64_t>(static_cast<uint32_t>(k.y())) * 19349663u) ^
                     (static_cast<uint64_t>(static_cast<uint32_t>(k.z())) * 83492791u);
  return static_cast<std::size_t>(h);
}

PointGrid::PointGrid(const std::vector<Eigen::Vector3d>& points, double cell_m)
    : cell_m_(cell_m), points_(points) {
  if (!(cell_m > 0) || !std::isfinite(cell_m)) {
    throw InvalidArgument("PointGrid: cell_m must be finite and > 0");
  }
  for (std::size_t i = 0; i < points_.size(); ++i) {
    cells_[Key(points_[i])].push_back(static_cast<uint32_t>(i));
  }
}

Eigen::Vector3i PointGrid::KeyOf(const Eigen::Vector3d& p, double cell_m) {
  return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / cell_m)),
                         static_cast<int>(std::floor(p.y() / cell_m)),
                         static_cast<int>(std::floor(p.z() / cell_m)));
}

Eigen::Vector3i PointGrid::Key(const Eigen::Vector3d& p) const { return KeyOf(p, cell_m_); }

std::optional<double> PointGrid::Nearest(const Eigen::Vector3d& p, double radius_m) const {
  const double radius = std::min(radius_m, cell_m_);
  double best = radius * radius;
  bool found = false;
  const Eigen::Vector3i key = Key(p);
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        const auto it = cells_.find(key + Eigen::Vector3i(dx, dy, dz));
        if (it == cells_.end()) continue;
        for (uint32_t i : it->second) {
          const double d2 = (points_[i] - p).squaredNorm();
          if (d2 <= best) {
            best = d2;
            found = true;
          }
        }
      }
    }
  }
  if (!found) return std::nullopt;
  return std::sqrt(best);
}

std::vector<Eigen::Vector3d> Thin(const std::vector<Eigen::Vector3d>& points, double cell_m) {
  if (!(cell_m > 0)) throw InvalidArgument("Thin: cell_m must be > 0");
  std::unordered_set<Eigen::Vector3i, PointGrid::KeyHash> seen;
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : points) {
    if (seen.insert(PointGrid::KeyOf(p, cell_m)).second) out.push_back(p);
  }
  return out;
}

MapScore ScoreMap(const std::vector<Eigen::Vector3d>& map_points,
                  const std::vector<Eigen::Vector3d>& truth, const ScoreOptions& options) {
  const auto in_band = [&](const Eigen::Vector3d& p) {
    const double r = (p - options.viewpoint).norm();
    return r >= options.min_range_m && r <= options.max_range_m;
  };
  std::vector<Eigen::Vector3d> map_in, truth_in;
  for (const Eigen::Vector3d& p : map_points) {
    if (in_band(p)) map_in.push_back(p);
  }
  for (const Eigen::Vector3d& p : truth) {
    if (in_band(p)) truth_in.push_back(p);
  }
  MapScore score;
  score.truth_samples = static_cast<int64_t>(truth_in.size());
  score.map_points = static_cast<int64_t>(map_in.size());
  if (!truth_in.empty()) {
    const PointGrid map_grid(map_in, options.within_m);
    int64_t covered = 0;
    for (const Eigen::Vector3d& p : truth_in)
      covered += map_grid.Nearest(p, options.within_m) ? 1 : 0;
    score.completeness = static_cast<double>(covered) / score.truth_samples;
  }
  if (!map_in.empty()) {
    // The full set of truth samples, so that a map point near the band's edge finds its surface.
    const PointGrid truth_grid(truth, options.far_m);
    std::vector<double> distances;
    distances.reserve(map_in.size());
    double sum = 0.0, sum_sq = 0.0;
    for (const Eigen::Vector3d& p : map_in) {
      const std::optional<double> d = truth_grid.Nearest(p, options.far_m);
      const double value = d.value_or(options.far_m);
      score.outliers += d ? 0 : 1;
      distances.push_back(value);
      sum += value;
      sum_sq += value * value;
    }
    const double n = static_cast<double>(distances.size());
    score.mean_m = sum / n;
    score.rms_m = std::sqrt(sum_sq / n);
    const std::size_t k =
        std::min(distances.size() - 1, static_cast<std::size_t>(std::ceil(0.95 * n)) - 1);
    std::nth_element(distances.begin(), distances.begin() + static_cast<std::ptrdiff_t>(k),
                     distances.end());
    score.p95_m = distances[k];
  }
  return score;
}

}  // namespace saccade::mapping
