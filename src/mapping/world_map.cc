#include "saccade/mapping/world_map.h"

#include <octomap/OcTree.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <utility>

#include "saccade/core/error.h"
#include "saccade/core/temporary_file.h"

namespace saccade::mapping {
namespace world_map_internal {

octomap::point3d ToOcto(const Eigen::Vector3d& p) {
  return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                          static_cast<float>(p.z()));
}

// A voxel's key as a Morton code (the three 16-bit coordinates' bits interleaved): sorted, the
// codes follow the octree's own order, so that updates in that order descend the same branches
// one after another.
uint64_t Spread(uint64_t v) {
  v &= 0xffff;
  v = (v | (v << 16)) & 0x0000ff0000ff;
  v = (v | (v << 8)) & 0x00f00f00f00f;
  v = (v | (v << 4)) & 0x0c30c30c30c3;
  v = (v | (v << 2)) & 0x249249249249;
  return v;
}

uint16_t Compact(uint64_t v) {
  v &= 0x249249249249;
  v = (v | (v >> 2)) & 0x0c30c30c30c3;
  v = (v | (v >> 4)) & 0x00f00f00f00f;
  v = (v | (v >> 8)) & 0x0000ff0000ff;
  v = (v | (v >> 16)) & 0xffff;
  return static_cast<uint16_t>(v);
}

uint64_t Morton(const octomap::OcTreeKey& key) {
  return Spread(key[0]) | (Spread(key[1]) << 1) | (Spread(key[2]) << 2);
}

octomap::OcTreeKey FromMorton(uint64_t code) {
  return octomap::OcTreeKey(Compact(code), Compact(code >> 1), Compact(code >> 2));
}

// Sorts 48-bit codes (a least-significant-digit radix sort, 16 bits a pass: the rays of one
// depth image cross millions of voxels, a comparison sort's log factor is 20) and drops repeats.
void SortUnique(std::vector<uint64_t>* codes, std::vector<uint64_t>* scratch) {
  constexpr int kBits = 16;
  constexpr std::size_t kBuckets = std::size_t{1} << kBits;
  scratch->resize(codes->size());
  std::vector<std::size_t> count(kBuckets);
  for (int shift = 0; shift < 48; shift += kBits) {
    std::fill(count.begin(), count.end(), 0);
    for (const uint64_t c : *codes) ++count[(c >> shift) & (kBuckets - 1)];
    std::size_t sum = 0;
    for (std::size_t& n : count) sum += std::exchange(n, sum);
    for (const uint64_t c : *codes) (*scratch)[count[(c >> shift) & (kBuckets - 1)]++] = c;
    codes->swap(*scratch);
  }
  codes->erase(std::unique(codes->begin(), codes->end()), codes->end());
}

}  // namespace world_map_internal

using world_map_internal::FromMorton;
using world_map_internal::Morton;
using world_map_internal::SortUnique;
using world_map_internal::ToOcto;

struct WorldMap::Impl {
  explicit Impl(double resolution) : tree(resolution) {}
  explicit Impl(const octomap::OcTree& other) : tree(other) {}  // its sensor model too
  octomap::OcTree tree;
  std::vector<uint64_t> scratch;  // the radix sort's buffer, kept between insertions
  octomap::KeyRay ray;            // the voxels of one ray (OctoMap's buffer is 600 KB)
  int64_t occupied = 0;           // finest voxels occupied
  int64_t known = 0;              // finest voxels known (free or occupied)

  // One log-odds update of the voxel at `key`, the counts kept.
  void Update(const octomap::OcTreeKey& key, bool hit);
  // The rays from `origin` to the centres of the end voxels `ends` (sorted Morton codes): the
  // end voxels within `max_range` (hits) and the voxels the rays cross (crossed), sorted, each
  // once. An end voxel whose centre lies beyond max_range is no hit; its ray stops at the range.
  void Rays(const octomap::point3d& origin, const std::vector<uint64_t>& ends, double max_range,
            std::vector<uint64_t>* hits, std::vector<uint64_t>* crossed);
};

void WorldMap::Impl::Rays(const octomap::point3d& origin, const std::vector<uint64_t>& ends,
                          double max_range, std::vector<uint64_t>* hits,
                          std::vector<uint64_t>* crossed) {
  hits->reserve(ends.size());
  for (const uint64_t code : ends) {
    const octomap::point3d centre = tree.keyToCoord(FromMorton(code));
    octomap::point3d end = centre;
    if ((centre - origin).norm() > max_range) {
      end = origin + (centre - origin).normalized() * static_cast<float>(max_range);
    } else {
      hits->push_back(code);
    }
    if (!tree.computeRayKeys(origin, end, ray)) continue;
    for (const octomap::OcTreeKey& key : ray) crossed->push_back(Morton(key));
  }
  SortUnique(crossed, &scratch);
}

void WorldMap::Impl::Update(const octomap::OcTreeKey& key, bool hit) {
  const octomap::OcTreeNode* before = tree.search(key);
  if (before != nullptr) {
    // Already clamped that way: no change (OctoMap's own early exit, without a second search).
    const float log_odds = before->getLogOdds();
    if (hit ? log_odds >= tree.getClampingThresMaxLog()
            : log_odds <= tree.getClampingThresMinLog()) {
      return;
    }
  }
  const bool was_occupied = before != nullptr && tree.isNodeOccupied(before);
  const octomap::OcTreeNode* after = tree.updateNode(key, hit, false);
  known += before == nullptr ? 1 : 0;
  occupied += (tree.isNodeOccupied(after) ? 1 : 0) - (was_occupied ? 1 : 0);
}

bool WorldMap::Options::IsValid(std::string* error) const {
  std::string what;
  if (!kResolutions.Contains(resolution_m)) {
    what = kResolutions.Refusal("resolution_m", resolution_m);
  } else if (!kRanges.Contains(max_range_m)) {
    what = kRanges.Refusal("max_range_m", max_range_m);
  } else if (!kStrides.Contains(stride)) {
    what = kStrides.Refusal("stride", stride);
  } else if (!kConfidences.Contains(min_confidence)) {
    what = kConfidences.Refusal("min_confidence", min_confidence);
  } else if (!kEdgeRatios.Contains(edge_ratio)) {
    what = kEdgeRatios.Refusal("edge_ratio", edge_ratio);
  } else if (!kHits.Contains(hit_probability)) {
    what = kHits.Refusal("hit_probability", hit_probability);
  } else if (!kMisses.Contains(miss_probability)) {
    what = kMisses.Refusal("miss_probability", miss_probability);
  } else if (!kThresholds.Contains(occupancy_threshold)) {
    what = kThresholds.Refusal("occupancy_threshold", occupancy_threshold);
  }
  if (what.empty()) return true;
  if (error) *error = "WorldMap::Options: " + what;
  return false;
}

WorldMap::WorldMap(const Options& options) : options_(options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument(error);
  impl_ = std::make_unique<Impl>(options.resolution_m);
  impl_->tree.setProbHit(options.hit_probability);
  impl_->tree.setProbMiss(options.miss_probability);
  impl_->tree.setOccupancyThres(options.occupancy_threshold);
}

WorldMap::~WorldMap() = default;
// The octree and the counts; the scratch buffers start empty.
WorldMap::WorldMap(const WorldMap& other)
    : options_(other.options_), impl_(std::make_unique<Impl>(other.impl_->tree)) {
  impl_->occupied = other.impl_->occupied;
  impl_->known = other.impl_->known;
}
WorldMap::WorldMap(WorldMap&&) noexcept = default;
WorldMap& WorldMap::operator=(WorldMap&&) noexcept = default;

FuseStats WorldMap::Fuse(const vision::StereoDepth& stereo) {
  // The samples of every stride-th row and column, confident enough and not on a depth edge: a
  // pixel whose neighbours (one pixel away) differ in depth by more than edge_ratio of its own
  // may have mixed the two surfaces (a "flying pixel" between foreground and background).
  std::vector<Eigen::Vector3d> points;
  const Image& depth = stereo.depth;
  const Eigen::Matrix3d K_inv = stereo.rectified.Matrix().inverse();
  const auto at = [&](const Image& image, int u, int v) {
    return reinterpret_cast<const float*>(image.data() + v * image.stride())[u];
  };
  for (int v = 1; v + 1 < depth.height(); v += options_.stride) {
    for (int u = 1; u + 1 < depth.width(); u += options_.stride) {
      const float z = at(depth, u, v);
      if (!(z > 0) || at(stereo.confidence, u, v) < options_.min_confidence) continue;
      bool edge = false;
      for (const auto& [du, dv] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
        const float n = at(depth, u + du, v + dv);
        edge = edge || !(n > 0) || std::abs(n - z) > options_.edge_ratio * z;
      }
      if (edge) continue;
      points.push_back(stereo.X_WR * (z * (K_inv * Eigen::Vector3d(u, v, 1.0))));
    }
  }
  return FusePoints(points, stereo.X_WR.translation());
}

FuseStats WorldMap::FusePoints(const std::vector<Eigen::Vector3d>& points_W,
                               const Eigen::Vector3d& origin_W) {
  // OctoMap's discretized insertion (insertPointCloud with discretize, the same map): one ray
  // per end voxel, to its centre, since at 2 m a 2 cm voxel holds several samples of a half-size
  // depth image; a voxel crossed by one ray and hit by another is a hit. Done here with sorted
  // Morton codes in place of OctoMap's hash sets, and the updates in the octree's own order:
  // a third of the time (bench/baselines/explore-2core.md).
  FuseStats stats;
  octomap::OcTree& tree = impl_->tree;
  std::vector<uint64_t> ends;
  ends.reserve(points_W.size());
  for (const Eigen::Vector3d& p : points_W) {
    octomap::OcTreeKey key;
    if (!p.allFinite() || (p - origin_W).norm() > options_.max_range_m ||
        !tree.coordToKeyChecked(ToOcto(p), key)) {
      continue;
    }
    ends.push_back(Morton(key));
    ++stats.rays;
  }
  SortUnique(&ends, &impl_->scratch);
  std::vector<uint64_t> hits, crossed;
  impl_->Rays(ToOcto(origin_W), ends, options_.max_range_m, &hits, &crossed);
  std::vector<uint64_t> misses;
  misses.reserve(crossed.size());
  std::set_difference(crossed.begin(), crossed.end(), hits.begin(), hits.end(),
                      std::back_inserter(misses));
  for (const uint64_t code : misses) impl_->Update(FromMorton(code), false);
  for (const uint64_t code : hits) impl_->Update(FromMorton(code), true);
  stats.occupied = occupied_voxels();
  stats.known_voxels = known_voxels();
  return stats;
}

Occupancy WorldMap::At(const Eigen::Vector3d& p_W) const {
  const octomap::OcTreeNode* node = impl_->tree.search(ToOcto(p_W));
  if (node == nullptr) return Occupancy::kUnknown;
  return impl_->tree.isNodeOccupied(node) ? Occupancy::kOccupied : Occupancy::kFree;
}

std::vector<Eigen::Vector3d> WorldMap::OccupiedCentres() const {
  std::vector<Eigen::Vector3d> out;
  const octomap::OcTree& tree = impl_->tree;
  const double resolution = tree.getResolution();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const double size = it.getSize();
    const octomap::point3d c = it.getCoordinate();
    if (size <= resolution * 1.5) {
      out.emplace_back(c.x(), c.y(), c.z());
      continue;
    }
    // A pruned leaf stands for a block of finest voxels: give each of them.
    const int n = static_cast<int>(std::lround(size / resolution));
    const double first = -size / 2 + resolution / 2;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        for (int k = 0; k < n; ++k) {
          out.emplace_back(c.x() + first + i * resolution, c.y() + first + j * resolution,
                           c.z() + first + k * resolution);
        }
      }
    }
  }
  return out;
}

RayEnd WorldMap::FirstAlong(const Eigen::Vector3d& origin_W, const Eigen::Vector3d& direction_W,
                            double max_range_m, double* distance_m) const {
  const octomap::OcTree& tree = impl_->tree;
  const Eigen::Vector3d d = direction_W.normalized();
  const octomap::point3d origin = ToOcto(origin_W);
  // A buffer per thread: queries (const) may run concurrently, as long as nothing is fused.
  thread_local octomap::KeyRay ray;
  RayEnd what = RayEnd::kNothing;
  double along = max_range_m;
  if (tree.computeRayKeys(origin, ToOcto(origin_W + max_range_m * d), ray)) {
    for (std::size_t i = 1; i < ray.size(); ++i) {  // after the origin's voxel
      const octomap::OcTreeKey& key = ray.begin()[i];
      const octomap::OcTreeNode* node = tree.search(key);
      if (node != nullptr && node->getLogOdds() <= 0) continue;  // free
      what = node == nullptr             ? RayEnd::kUnknown
             : tree.isNodeOccupied(node) ? RayEnd::kOccupied
                                         : RayEnd::kTentative;
      const octomap::point3d c = tree.keyToCoord(key);
      along = std::min(max_range_m, (Eigen::Vector3d(c.x(), c.y(), c.z()) - origin_W).dot(d));
      break;
    }
  }
  if (distance_m != nullptr) *distance_m = along;
  return what;
}

int64_t WorldMap::occupied_voxels() const { return impl_->occupied; }

int64_t WorldMap::known_voxels() const { return impl_->known; }

std::size_t WorldMap::memory_bytes() const { return impl_->tree.memoryUsage(); }

void WorldMap::WritePly(const std::filesystem::path& path) const {
  WritePointsPly(OccupiedCentres(), path);
}

void WritePointsPly(const std::vector<Eigen::Vector3d>& points, const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  const std::filesystem::path temporary = TemporaryPathFor(path, counter++);
  std::FILE* file = std::fopen(temporary.c_str(), "wb");
  if (file == nullptr) {
    throw FileError(path.string(), 0, "", std::string("cannot write: ") + std::strerror(errno));
  }
  const std::string header =
      "ply\nformat binary_little_endian 1.0\ncomment saccade map, metres, "
      "world frame (z up)\nelement vertex " +
      std::to_string(points.size()) +
      "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  bool ok = std::fwrite(header.data(), 1, header.size(), file) == header.size();
  for (const Eigen::Vector3d& p : points) {
    const float xyz[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()),
                          static_cast<float>(p.z())};
    ok = ok && std::fwrite(xyz, sizeof(float), 3, file) == 3;
  }
  ok = std::fflush(file) == 0 && ok;
  std::fclose(file);
  if (!ok) {
    std::filesystem::remove(temporary);
    throw FileError(path.string(), 0, "", "cannot write the PLY (disk full or I/O error)");
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary);
    throw FileError(path.string(), 0, "", "cannot rename into place: " + error.message());
  }
}

}  // namespace saccade::mapping
