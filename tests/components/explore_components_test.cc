// Exploration as pipeline components (pipelines/explore.yaml, issue 44): the loop of rendered
// eyes -> dense stereo -> map, and attention -> fixation -> motors, without ground truth; the map
// it builds is then scored against the scene's ground truth (components/explore_session.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "saccade/components/explore_session.h"
#include "saccade/components/messages.h"
#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/mapping/inhibition_3d.h"
#include "saccade/mapping/map_score.h"
#include "saccade/mapping/world_map.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "scratch_dir.h"

namespace saccade::components {
namespace {

const std::string kSource = SACCADE_SOURCE_DIR;

// The map's topic (sensor_msgs/PointCloud2 over DDS) is the DDS tests' (tests/dds): this test
// program has no topic transport, so the pipeline's outputs stay in the process.
void NoTopics(runtime::PipelineSpec& spec) {
  for (auto& c : spec.components) c.topic_outputs.clear();
}

struct ExploreRun {
  std::vector<MapMessage> maps;          // every map emitted
  std::set<int64_t> targets;             // target ids sent
  std::set<std::string> sources;         // what proposed them
  std::vector<head::JointState> joints;  // per step
  std::shared_ptr<const scene::Scene> scene;
};

// pipelines/explore.yaml on `scene_file` (and `head_file` in place of its head) for `steps`.
ExploreRun RunExplore(const std::string& scene_file, int steps,
                      const std::function<void(runtime::PipelineSpec&)>& change = {},
                      const std::string& head_file = "") {
  RegisterComponents();
  runtime::PipelineSpec spec = runtime::LoadPipelineFile(kSource + "/pipelines/explore.yaml");
  spec.resources["scene"] = runtime::ResourceSpec{scene_file, "explore_components_test", 0};
  NoTopics(spec);
  if (change) change(spec);
  runtime::Pipeline pipeline =
      head_file.empty() ? runtime::Pipeline::Build(spec)
                        : runtime::Pipeline::Build(spec, RegistryWithHead(head_file, "test"));
  ExploreRun out;
  out.scene = pipeline.resources().Default<scene::Scene>("scene");
  for (const auto& c : pipeline.components()) {
    for (const auto& o : c->outputs()) {
      if (auto* m = dynamic_cast<runtime::Output<MapMessage>*>(o.get())) {
        m->signal().Connect([&](const MapMessage& map) { out.maps.push_back(map); });
      } else if (auto* t = dynamic_cast<runtime::Output<TargetMessage>*>(o.get())) {
        t->signal().Connect([&](const TargetMessage& target) {
          if (target.valid && target.source.rfind("explore_", 0) == 0) {
            out.targets.insert(target.target_id);
            out.sources.insert(target.source);
          }
        });
      } else if (auto* j = dynamic_cast<runtime::Output<JointStateMessage>*>(o.get())) {
        j->signal().Connect([&](const JointStateMessage& m) { out.joints.push_back(m.positions); });
      }
    }
  }
  runtime::RunOptions options;
  options.steps = steps;
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline, options);
  EXPECT_TRUE(summary.errors.empty());
  return out;
}

TEST(ExplorePipeline, MapsTheWallWithoutTruthAndTheMapLiesOnItsSurfaces) {
  const std::filesystem::path ply = testing_helpers::ScratchFile("explore_wall.ply");
  const ExploreRun run =
      RunExplore(kSource + "/scenes/explore_wall.yaml", 100, [&](runtime::PipelineSpec& spec) {
        for (auto& c : spec.components) {
          if (c.name == "map") c.params["ply"] = ply.string();
        }
      });
  // Four simulated seconds: the head went to many places, fusing a depth at each rest.
  EXPECT_GE(run.targets.size(), 6u);
  // Proposed by saliency zones and by the reach's novelty (the map's unknown space); a face the
  // second stage finds in the best zone is a third kind (tests/components/explore_attention_test).
  EXPECT_TRUE(run.sources.count("explore_saliency"));
  EXPECT_TRUE(run.sources.count("explore_reach"));
  for (const std::string& source : run.sources) {
    EXPECT_TRUE(source == "explore_face" || source == "explore_saliency" ||
                source == "explore_reach")
        << source;
  }
  ASSERT_GE(run.maps.size(), 5u);
  for (std::size_t i = 1; i < run.maps.size(); ++i) {
    EXPECT_EQ(run.maps[i].fused, run.maps[i - 1].fused + 1);
    EXPECT_GE(run.maps[i].time, run.maps[i - 1].time);
  }
  const MapMessage& last = run.maps.back();
  EXPECT_GT(last.occupied_W.size(), run.maps[1].occupied_W.size());  // it grew
  // Each message carries the map and the inhibition as they were when it was sent (the
  // attention's novelty reads them): later fusions left every snapshot as it was.
  for (const MapMessage& map : run.maps) {
    ASSERT_NE(map.map, nullptr);
    ASSERT_NE(map.ior, nullptr);
    EXPECT_EQ(map.map->occupied_voxels(), static_cast<int64_t>(map.occupied_W.size()));
    EXPECT_EQ(map.map->OccupiedCentres(), map.occupied_W);
    EXPECT_GE(map.ior->places().size(), map.inhibited.size());
  }
  EXPECT_GT(last.occupied_W.size(), 5000u);
  // Inhibition of return: the fixated places, strongest first, fading with time.
  ASSERT_GE(last.inhibited.size(), 3u);
  for (std::size_t i = 0; i < last.inhibited.size(); ++i) {
    EXPECT_GT(last.inhibited[i].strength, 0.0);
    EXPECT_LE(last.inhibited[i].strength, 1.0);
    EXPECT_DOUBLE_EQ(last.inhibited[i].radius_m, 0.3);
    if (i > 0) {
      EXPECT_LE(last.inhibited[i].strength, last.inhibited[i - 1].strength);
    }
  }
  EXPECT_LT(last.inhibited.back().strength, last.inhibited.front().strength);
  // Every posture within the joint limits.
  const head::HeadModel& head = run.scene->robot()->head;
  for (const head::JointState& joints : run.joints) {
    const Eigen::VectorXd q = head.Posture(joints);
    for (int i = 0; i < head.num_joints(); ++i) {
      EXPECT_GE(q[i], head.joint(i).limits.min - 1e-9);
      EXPECT_LE(q[i], head.joint(i).limits.max + 1e-9);
    }
  }
  // Scored against the truth the pipeline never saw: the map lies on the wall's surfaces.
  ExploreOptions truth_options;
  truth_options.truth_step = 1.0;
  truth_options.truth_cell_m = 0.02;
  const ExploreTruth truth = MakeExploreTruth(*run.scene, truth_options);
  const mapping::MapScore score = mapping::ScoreMap(last.occupied_W, truth.samples_W);
  std::cout << run.targets.size() << " targets, " << last.fused << " depths, "
            << last.occupied_W.size() << " voxels, completeness " << score.completeness << ", RMS "
            << score.rms_m * 1000 << " mm, outliers " << score.outliers << "\n";
  EXPECT_LT(score.rms_m, 0.02);
  EXPECT_GT(score.completeness, 0.10);
  // The PLY written at the end holds the final map.
  ASSERT_TRUE(std::filesystem::exists(ply));
  EXPECT_GT(std::filesystem::file_size(ply), last.occupied_W.size() * 12);
}

// Every part on another head: the humanoid (loaded from its URDF, 6.8 cm baseline).
TEST(ExplorePipeline, RunsOnTheHumanoidHead) {
  const ExploreRun run =
      RunExplore(kSource + "/scenes/explore_wall.yaml", 60, {}, kSource + "/robots/humanoid.yaml");
  EXPECT_GE(run.targets.size(), 3u);
  ASSERT_GE(run.maps.size(), 2u);
  EXPECT_GT(run.maps.back().fused, 1);
}

TEST(ExplorePipeline, BadParametersAreRefusedNamingTheComponentAndTheKey) {
  RegisterComponents();
  runtime::PipelineSpec spec = runtime::LoadPipelineFile(kSource + "/pipelines/explore.yaml");
  NoTopics(spec);
  for (auto& c : spec.components) {
    if (c.name == "map") c.params["resolution_m"] = 0.0;
  }
  try {
    runtime::Pipeline::Build(spec);
    FAIL() << "a resolution of 0 was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("map"), std::string::npos) << what;
    EXPECT_NE(what.find("resolution_m"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace saccade::components
