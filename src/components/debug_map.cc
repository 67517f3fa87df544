#include "saccade/components/debug_map.h"

#include <algorithm>
#include <cmath>

namespace saccade::components {
namespace debug_map {

constexpr double kBottomZ = 0.2;           // m: the wall's lowest row
constexpr double kInhibitedRadius = 0.15;  // m
constexpr double kForgotten = 0.05;        // strength below which a place is dropped

}  // namespace debug_map

DebugMap::DebugMap() : map_(AddOutput<MapMessage>("map")) {
  DeclareParam("resolution_m", &resolution_m_, "voxel edge").Min(1e-4).Max(10).Unit("m");
  DeclareParam("distance_m", &distance_m_, "the wall's x in the world").Unit("m");
  DeclareParam("columns", &columns_, "voxels in a row of the wall").Min(1).Max(100000);
  DeclareParam("voxels_per_step", &voxels_per_step_, "voxels added each step").Min(0);
  DeclareParam("max_voxels", &max_voxels_, "the wall stops growing there").Min(0).Max(10000000);
  DeclareParam("inhibit_every_steps", &inhibit_every_steps_,
               "a new inhibited place every this many steps (0: none)")
      .Min(0);
  DeclareParam("decay_s", &decay_s_, "time constant of the places' strength").Min(1e-3).Unit("s");
}

void DebugMap::Step(const runtime::StepContext& context) {
  const int64_t target =
      std::min(max_voxels_, static_cast<int64_t>(occupied_.size()) + voxels_per_step_);
  for (auto i = static_cast<int64_t>(occupied_.size()); i < target; ++i) {
    const double y = (static_cast<double>(i % columns_) - 0.5 * (columns_ - 1)) * resolution_m_;
    const double z = debug_map::kBottomZ + static_cast<double>(i / columns_) * resolution_m_;
    occupied_.emplace_back(distance_m_, y, z);
  }
  if (inhibit_every_steps_ > 0 && context.step % inhibit_every_steps_ == 0 && !occupied_.empty()) {
    visits_.push_back({occupied_.back(), context.time});
  }
  MapMessage m;
  m.time = context.time;
  m.frame_index = context.step;
  m.resolution_m = resolution_m_;
  m.occupied_W = occupied_;
  m.fused = context.step + 1;
  for (const Visit& v : visits_) {
    const double strength = std::exp(-(context.time - v.time) / decay_s_);
    if (strength >= debug_map::kForgotten) {
      m.inhibited.push_back({v.p_W, debug_map::kInhibitedRadius, strength});
    }
  }
  std::sort(
      m.inhibited.begin(), m.inhibited.end(),
      [](const InhibitedPlace& a, const InhibitedPlace& b) { return a.strength > b.strength; });
  map_.Emit(m);
}

}  // namespace saccade::components
