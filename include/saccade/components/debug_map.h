#pragma once
#include <cstdint>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/runtime/component.h"

namespace saccade::components {

/// debug.map -- a synthetic map that grows, to see the map's viewers work while no mapper runs
/// (the GUI's 3D view; rviz2 or Foxglove on a `map: {topic: map}` output): each step adds
/// `voxels_per_step` voxels to a wall facing the head at x = `distance_m` (rows of `columns`
/// voxels of `resolution_m`, centred on y = 0, from z = 0.2 m up) until it holds `max_voxels`,
/// and every `inhibit_every_steps` steps inhibits the place of its newest voxel (radius
/// 0.15 m, strength exp(-age / `decay_s`), forgotten below 0.05). Output: map (mapping.map),
/// every step. Deterministic: the same steps give the same maps.
class DebugMap : public runtime::Component {
 public:
  DebugMap();
  void Step(const runtime::StepContext& context) override;

 private:
  double resolution_m_ = 0.05;
  double distance_m_ = 2.0;
  int64_t columns_ = 40;
  int64_t voxels_per_step_ = 20;
  int64_t max_voxels_ = 2000;
  int64_t inhibit_every_steps_ = 25;
  double decay_s_ = 5.0;
  runtime::Output<MapMessage>& map_;
  std::vector<Eigen::Vector3d> occupied_;
  struct Visit {
    Eigen::Vector3d p_W;
    double time;
  };
  std::vector<Visit> visits_;
};

}  // namespace saccade::components
