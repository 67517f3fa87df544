// `saccade explore`'s settings file (config/explore.yaml documents it).
#include <algorithm>

#include "core/internal_yaml.h"
#include "saccade/components/explore_session.h"
#include "saccade/core/error.h"

namespace saccade::components {
namespace explore_config_internal {

using ::saccade::internal::Entry;

// A number in `range`, or a FileError at its line naming the key and the range.
double InRange(const Entry& entry, const Interval& range) {
  const double value = entry.AsDouble();
  if (!range.Contains(value)) {
    entry.Fail("expected a number in " + range.Text() + ", got " + entry.node().Scalar());
  }
  return value;
}

void ReadIf(const Entry& map, const char* key, const Interval& range, double* out) {
  if (const std::optional<Entry> entry = map.Find(key)) *out = InRange(*entry, range);
}

void ReadIf(const Entry& map, const char* key, const Interval& range, int* out) {
  if (const std::optional<Entry> entry = map.Find(key)) {
    *out = static_cast<int>(
        entry->AsInteger(static_cast<int64_t>(range.min), static_cast<int64_t>(range.max)));
  }
}

void ReadStereo(const Entry& entry, vision::DenseStereo::Options* o) {
  using S = vision::DenseStereo::Options;
  entry.ExpectMap({"scale", "min_depth_m", "block_size", "uniqueness_ratio", "speckle_window",
                   "left_right_check", "lr_max_diff_px"});
  ReadIf(entry, "scale", S::kScales, &o->scale);
  ReadIf(entry, "min_depth_m", S::kMinDepths, &o->min_depth_m);
  ReadIf(entry, "block_size", S::kBlockSizes, &o->block_size);
  if (o->block_size % 2 == 0) entry.Get("block_size").Fail("expected an odd number in 1..11");
  ReadIf(entry, "uniqueness_ratio", S::kUniquenessRatios, &o->uniqueness_ratio);
  ReadIf(entry, "speckle_window", S::kSpeckleWindows, &o->speckle_window);
  if (const std::optional<Entry> e = entry.Find("left_right_check")) {
    o->left_right_check = e->AsBool();
  }
  ReadIf(entry, "lr_max_diff_px", S::kLrDiffs, &o->lr_max_diff_px);
}

void ReadMap(const Entry& entry, mapping::WorldMap::Options* o) {
  using M = mapping::WorldMap::Options;
  entry.ExpectMap({"resolution_m", "max_range_m", "stride", "min_confidence", "edge_ratio",
                   "hit_probability", "miss_probability", "occupancy_threshold"});
  ReadIf(entry, "resolution_m", M::kResolutions, &o->resolution_m);
  ReadIf(entry, "max_range_m", M::kRanges, &o->max_range_m);
  ReadIf(entry, "stride", M::kStrides, &o->stride);
  ReadIf(entry, "min_confidence", M::kConfidences, &o->min_confidence);
  ReadIf(entry, "edge_ratio", M::kEdgeRatios, &o->edge_ratio);
  ReadIf(entry, "hit_probability", M::kHits, &o->hit_probability);
  ReadIf(entry, "miss_probability", M::kMisses, &o->miss_probability);
  ReadIf(entry, "occupancy_threshold", M::kThresholds, &o->occupancy_threshold);
}

constexpr Interval kPositive = Interval::Above(0.0);
constexpr Interval kNonNegative = Interval::AtLeast(0.0);

}  // namespace explore_config_internal

ExploreConfig LoadExploreConfig(const std::filesystem::path& path) {
  using namespace explore_config_internal;
  const std::string file = path.string();
  const std::string text = ::saccade::internal::ReadConfigFile(path, "explore settings");
  const Entry root(::saccade::internal::ParseYaml(text, file), "", &file, 1);
  ExploreConfig config;
  if (root.IsNull()) return config;
  root.ExpectMap({"strategies", "seconds", "dwell_s", "seed", "target_distance_m", "raster_step",
                  "attention", "ior", "stereo", "map", "score"},
                 "explore settings");
  ExploreOptions& o = config.options;
  if (const std::optional<Entry> strategies = root.Find("strategies")) {
    config.strategies.clear();
    for (const Entry& s : strategies->AsSequence("strategies")) {
      const std::string name = s.AsNonEmptyString();
      const std::vector<std::string>& known = ExploreStrategies();
      if (std::find(known.begin(), known.end(), name) == known.end()) {
        s.Fail("'" + name + "' is not a strategy, expected raster, random or saliency");
      }
      config.strategies.push_back(name);
    }
    if (config.strategies.empty()) strategies->Fail("expected at least one strategy");
  }
  ReadIf(root, "seconds", kPositive, &o.seconds);
  ReadIf(root, "dwell_s", kPositive, &o.dwell_s);
  if (const std::optional<Entry> e = root.Find("seed")) o.seed = e->AsUint64();
  ReadIf(root, "target_distance_m", kPositive, &o.target_distance_m);
  ReadIf(root, "raster_step", Interval::LeftOpen(0.0, 2.0), &o.raster_step);
  if (const std::optional<Entry> e = root.Find("attention")) {
    e->ExpectMap({"candidate_step", "saliency_weight", "novelty_weight", "tentative_value"});
    ReadIf(*e, "candidate_step", Interval::LeftOpen(0.0, 2.0), &o.candidate_step);
    ReadIf(*e, "saliency_weight", kNonNegative, &o.saliency_weight);
    ReadIf(*e, "novelty_weight", kNonNegative, &o.novelty_weight);
    ReadIf(*e, "tentative_value", kNonNegative, &o.tentative_value);
  }
  if (const std::optional<Entry> e = root.Find("ior")) {
    e->ExpectMap({"time_constant_s", "radius_m"});
    ReadIf(*e, "time_constant_s", kPositive, &o.ior_time_constant_s);
    ReadIf(*e, "radius_m", kPositive, &o.ior_radius_m);
  }
  if (const std::optional<Entry> e = root.Find("stereo")) ReadStereo(*e, &o.stereo);
  if (const std::optional<Entry> e = root.Find("map")) ReadMap(*e, &o.map);
  if (const std::optional<Entry> e = root.Find("score")) {
    e->ExpectMap({"sample_every_s", "truth_cell_m", "truth_step"});
    ReadIf(*e, "sample_every_s", kPositive, &o.sample_every_s);
    ReadIf(*e, "truth_cell_m", kPositive, &o.truth_cell_m);
    ReadIf(*e, "truth_step", Interval::LeftOpen(0.0, 2.0), &o.truth_step);
  }
  return config;
}

}  // namespace saccade::components
