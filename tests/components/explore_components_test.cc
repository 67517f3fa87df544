// Exploration as pipeline components (pipelines/explore.yaml, issue 44): the loop of rendered
// eyes -> dense stereo -> map, and attention -> fixation -> motors, without ground truth; the map
// it builds is then scored against the scene's ground truth (components/explore_session.h).
#include <gtest/gtest.h>

#include <cmath>
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
#include "saccade/runtime/component_registry.h"
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

// The map's inhibition of return on a moving face: a place fixated on a face of `candidates`
// moves with the face's track, so the face stays inhibited where it walks to and where it was
// is free; without `candidates` the place stays where the face was.
TEST(ExplorePipeline, APlaceFixatedOnAFaceMovesWithIt) {
  RegisterComponents();
  const auto run = [](bool with_faces) {
    std::unique_ptr<runtime::Component> map =
        runtime::ComponentRegistry::Global().Create("mapping.world_map");
    map->Initialise("map", 1, {}, nullptr);
    map->Configure({{"ior_time_constant_s", 10.0}, {"ior_radius_m", 0.3}});
    auto& selection = dynamic_cast<runtime::Input<SelectionMessage>&>(*map->FindInput("selection"));
    auto& faces = dynamic_cast<runtime::Input<CandidatesMessage>&>(*map->FindInput("candidates"));
    auto& depth = dynamic_cast<runtime::Input<DepthMessage>&>(*map->FindInput("depth"));
    std::optional<MapMessage> last;
    dynamic_cast<runtime::Output<MapMessage>&>(*map->FindOutput("map"))
        .signal()
        .Connect([&](const MapMessage& m) { last = m; });
    const Eigen::Vector3d start(2.0, -0.6, 1.5), step(0.0, 0.04, 0.0);  // 1 m/s at 25 Hz
    runtime::StepContext context;
    context.dt = 0.04;
    for (int k = 0; k <= 30; ++k) {
      context.step = k;
      context.time = k * context.dt;
      const Eigen::Vector3d face = start + k * step;
      if (with_faces) {
        CandidatesMessage seen;
        seen.time = context.time;
        seen.candidates.push_back(FaceCandidate{});
        seen.candidates.back().p_W = face;
        seen.candidates.push_back(FaceCandidate{});  // another face, never fixated
        seen.candidates.back().p_W = Eigen::Vector3d(2.0, 1.5, 1.5);
        faces.Deliver(seen);
      }
      if (k == 0) {
        SelectionMessage fixated;
        fixated.valid = fixated.fixating = true;
        fixated.p_W = face + Eigen::Vector3d(0.0, 0.0, 0.05);  // on the face, a little off
        selection.Deliver(fixated);
      }
      if (k == 30) {  // an empty depth: a map is emitted
        DepthMessage empty;
        auto stereo = std::make_shared<vision::StereoDepth>();
        stereo->rectified = geometry::Intrinsics(8, 6, 5.0, 5.0, 3.5, 2.5);
        stereo->depth = Image(8, 6, PixelFormat::kFloat32);
        stereo->confidence = Image(8, 6, PixelFormat::kFloat32);
        stereo->disparity = Image(8, 6, PixelFormat::kFloat32);
        empty.stereo = stereo;
        depth.Deliver(empty);
      }
      map->Step(context);
      for (const auto& input : map->inputs()) input->MarkSeen();  // as the scheduler does
    }
    return last;
  };
  const Eigen::Vector3d start(2.0, -0.6, 1.5), end(2.0, 0.6, 1.5);
  const double decay = std::exp(-1.2 / 10.0);
  const std::optional<MapMessage> moving = run(true);
  ASSERT_TRUE(moving.has_value());
  ASSERT_TRUE(moving->ior);
  EXPECT_NEAR(moving->ior->Inhibition(end, 1.2), decay, 1e-9);
  EXPECT_EQ(moving->ior->Inhibition(start, 1.2), 0.0);
  EXPECT_EQ(moving->ior->Inhibition(Eigen::Vector3d(2.0, 1.5, 1.5), 1.2), 0.0);
  ASSERT_EQ(moving->inhibited.size(), 1u);
  EXPECT_NEAR((moving->inhibited[0].p_W - (end + Eigen::Vector3d(0, 0, 0.05))).norm(), 0.0, 1e-9);
  const std::optional<MapMessage> still = run(false);
  ASSERT_TRUE(still.has_value());
  EXPECT_EQ(still->ior->Inhibition(end, 1.2), 0.0);
  EXPECT_NEAR(still->ior->Inhibition(start, 1.2), decay, 1e-9);
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
