// debug.map (components/debug_map.h): the synthetic map that stands in for a mapper while the
// map's viewers are tried (the GUI's 3D view, DDS PointCloud2).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"

namespace saccade::components {
namespace {

// Strengths are exp() of exact times: equal to rounding.
constexpr double kStrengthTolerance = 1e-12;

std::string MapPipeline(const std::string& params) {
  return "clock: {mode: simulated, step: 0.1, steps: 30}\n"
         "components:\n"
         "  - name: map\n"
         "    type: debug.map\n"
         "    params: " +
         params + "\n";
}

TEST(DebugMap, GrowsAWallAndInhibitsPlacesThatFade) {
  RegisterComponents();
  runtime::Pipeline pipeline = runtime::Pipeline::LoadString(
      MapPipeline("{voxels_per_step: 10, max_voxels: 250, columns: 5, resolution_m: 0.1, "
                  "distance_m: 3, inhibit_every_steps: 10, decay_s: 1}"),
      "map.yaml");
  std::vector<MapMessage> maps;
  for (const auto& output : pipeline.Find("map")->outputs()) {
    auto* typed = dynamic_cast<runtime::Output<MapMessage>*>(output.get());
    ASSERT_NE(typed, nullptr);
    typed->signal().Connect([&](const MapMessage& m) { maps.push_back(m); });
  }
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline);
  ASSERT_EQ(summary.errors_total, 0) << summary.FullReport();
  ASSERT_EQ(maps.size(), 30u);

  // Step 0: two rows of five, centred on y = 0, from z = 0.2 up; its newest voxel inhibited.
  const MapMessage& first = maps[0];
  EXPECT_EQ(first.resolution_m, 0.1);
  ASSERT_EQ(first.occupied_W.size(), 10u);
  EXPECT_TRUE(first.occupied_W[0].isApprox(Eigen::Vector3d(3, -0.2, 0.2)));
  EXPECT_TRUE(first.occupied_W[4].isApprox(Eigen::Vector3d(3, 0.2, 0.2)));
  EXPECT_TRUE(first.occupied_W[5].isApprox(Eigen::Vector3d(3, -0.2, 0.3)));
  ASSERT_EQ(first.inhibited.size(), 1u);
  EXPECT_EQ(first.inhibited[0].p_W, first.occupied_W.back());
  EXPECT_EQ(first.inhibited[0].strength, 1.0);
  EXPECT_EQ(first.inhibited[0].radius_m, 0.15);

  // It grows by 10 a step up to 250 (step 24), then stays.
  EXPECT_EQ(maps[23].occupied_W.size(), 240u);
  EXPECT_EQ(maps[24].occupied_W.size(), 250u);
  EXPECT_EQ(maps[29].occupied_W.size(), 250u);

  // At 2.9 s the places of 0, 1 and 2 s hold exp(-age / 1 s), strongest first (exp(-2.9) =
  // 0.055 is still above the 0.05 at which a place is forgotten).
  const MapMessage& last = maps[29];
  ASSERT_EQ(last.inhibited.size(), 3u);
  EXPECT_NEAR(last.inhibited[0].strength, std::exp(-0.9), kStrengthTolerance);
  EXPECT_NEAR(last.inhibited[1].strength, std::exp(-1.9), kStrengthTolerance);
  EXPECT_NEAR(last.inhibited[2].strength, std::exp(-2.9), kStrengthTolerance);
  EXPECT_EQ(last.frame_index, 29);
}

TEST(DebugMap, ABadParameterNamesFileLineAndKey) {
  RegisterComponents();
  try {
    runtime::Pipeline::LoadString(MapPipeline("{resolution_m: 0}"), "map.yaml");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("map.yaml:5"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("resolution_m"));
  }
}

}  // namespace
}  // namespace saccade::components
