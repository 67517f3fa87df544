// One step of saccade.envs.FixationEnv done in C++, for comparison with the same step through
// Python (bench/python_env_bench.py runs both): check the action, move the joints for dt
// within their limits, forward kinematics and the axis errors, and draw both eyes through
// Renderer::RenderBatch (one head) into a buffer. The scene is the env's own, written by the
// Python bench to the file SACCADE_ENV_SCENE names (its eyes at the env's image size).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "saccade/head/kinematics.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace {

using saccade::head::JointState;

void BM_FixationEnvStep(benchmark::State& bench) {
  const char* path = std::getenv("SACCADE_ENV_SCENE");
  if (path == nullptr) {
    bench.SkipWithError("set SACCADE_ENV_SCENE (bench/python_env_bench.py does)");
    return;
  }
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  const saccade::scene::Scene scene = saccade::scene::Scene::FromYamlString(text.str(), path, ".");
  saccade::render::RendererOptions options;
  options.cameras = {"left", "right"};
  options.draw_robot = false;
  options.distortion = options.noise = options.motion_blur = false;
  auto renderer = saccade::render::MakeRenderer(scene, options);
  const auto& head = scene.robot()->head;
  const int w = scene.cameras()[0].model.intrinsics().width();
  const int h = scene.cameras()[0].model.intrinsics().height();
  std::vector<uint8_t> out(static_cast<std::size_t>(2) * w * h * 3);
  // The env's scene: the first three objects shown in front of the head, the rest hidden.
  saccade::render::BatchHead batch;
  const std::size_t n = scene.objects().size();
  batch.object_poses.resize(n);
  batch.hidden.assign(n, true);
  const Eigen::Vector3d base = head.X_WB().translation();
  for (std::size_t i = 0; i < std::min<std::size_t>(3, n); ++i) {
    batch.hidden[i] = false;
    saccade::geometry::Pose X = saccade::geometry::Pose::Identity();
    X.translation() = base + Eigen::Vector3d(2.0, -0.6 + 0.6 * i, 0.0);
    X.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    batch.object_poses[i] = X;
  }
  const Eigen::Vector3d target = batch.object_poses[0]->translation();
  const double dt = 0.04;
  const Eigen::Vector4d action(0.1, -0.05, 0.02, -0.02);  // rad/s
  JointState joints;
  int64_t step = 0;
  double error_sum = 0.0;
  // Outside the timing, as the env's reset: the first batch makes the framebuffer of tiles
  // and, on a software rasteriser, the second context (RendererOptions::batch_contexts).
  batch.state.joints = joints;
  renderer->RenderBatch({batch}, out.data(), out.size());
  for (auto _ : bench) {
    // The action: finite and within the velocity limits (refused otherwise in the env).
    for (int j = 0; j < 4; ++j) {
      const auto& limits = head.limits(saccade::head::kAllJoints[j]);
      if (!std::isfinite(action[j]) || std::abs(action[j]) > limits.max_velocity) {
        bench.SkipWithError("bad action");
        return;
      }
      double& q = joints[saccade::head::kAllJoints[j]];
      q = std::clamp(q + action[j] * dt, limits.min, limits.max);
    }
    const auto frames = saccade::head::ForwardKinematics(head, joints);
    for (const auto* X : {&frames.X_WCamLeft, &frames.X_WCamRight}) {
      const Eigen::Vector3d ray = (target - X->translation()).normalized();
      error_sum += std::acos(std::clamp(X->linear().col(2).dot(ray), -1.0, 1.0));
    }
    batch.state.time = static_cast<double>(++step) * dt;
    batch.state.joints = joints;
    renderer->RenderBatch({batch}, out.data(), out.size());
    benchmark::DoNotOptimize(out.data());
  }
  benchmark::DoNotOptimize(error_sum);
  bench.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(bench.iterations()), benchmark::Counter::kIsRate);
}
// The shared machine's load varies from second to second: many short repetitions, and the
// least disturbed one ("min") is the figure python_env_bench.py compares.
BENCHMARK(BM_FixationEnvStep)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.1)
    ->Repetitions(30)
    ->ComputeStatistics("min",
                        [](const std::vector<double>& v) {
                          return *std::min_element(v.begin(), v.end());
                        })
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
