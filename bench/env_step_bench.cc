// One step of saccade.envs.FixationEnv done in C++, for comparison with the same step through
// Python (bench/python_env_bench.py runs both, --benchmark_filter=BM_FixationEnvStep): check the
// action, move the joints for dt within their limits, forward kinematics and the axis errors, and
// draw both eyes through Renderer::RenderBatch (one head) into a buffer. The scene is the env's
// own, written by the Python bench to the file SACCADE_ENV_SCENE names (its eyes at the env's image
// size).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include "saccade/head/kinematics.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace {

using saccade::head::JointState;

// The env's scene, from the file SACCADE_ENV_SCENE names; none (the bench skipped) without it.
std::optional<saccade::scene::Scene> EnvScene(benchmark::State& bench) {
  const char* path = std::getenv("SACCADE_ENV_SCENE");
  if (path == nullptr) {
    bench.SkipWithError(
        "set SACCADE_ENV_SCENE to the env's scene (bench/python_env_bench.py "
        "writes one)");
    return std::nullopt;
  }
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return saccade::scene::Scene::FromYamlString(text.str(), path, ".");
}

// The env's renderer: both eyes, no robot, no effects.
std::unique_ptr<saccade::render::Renderer> EnvRenderer(const saccade::scene::Scene& scene,
                                                       int batch_contexts) {
  saccade::render::RendererOptions options;
  options.cameras = {"left", "right"};
  options.draw_robot = false;
  options.distortion = options.noise = options.motion_blur = false;
  options.batch_contexts = batch_contexts;
  return saccade::render::MakeRenderer(scene, options);
}

void BM_FixationEnvStep(benchmark::State& bench) {
  const std::optional<saccade::scene::Scene> env = EnvScene(bench);
  if (!env) return;
  const saccade::scene::Scene& scene = *env;
  auto renderer = EnvRenderer(scene, 0);
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
  JointState joints = head.Home();
  int64_t step = 0;
  double error_sum = 0.0;
  // Outside the timing, as the env's reset: the first batch makes the framebuffer of tiles
  // and, on a software rasteriser, the second context (RendererOptions::batch_contexts).
  batch.state.joints = joints;
  renderer->RenderBatch({batch}, out.data(), out.size());
  for (auto _ : bench) {
    // The action: finite and within the velocity limits (refused otherwise in the env).
    for (int j = 0; j < 4; ++j) {
      const auto& limits = head.joint(j).limits;
      if (!std::isfinite(action[j]) || std::abs(action[j]) > limits.max_velocity) {
        bench.SkipWithError("bad action");
        return;
      }
      double& q = joints[j];
      q = std::clamp(q + action[j] * dt, limits.min, limits.max);
    }
    const auto cameras = head.CameraPoses(joints);
    for (const auto* X : {&cameras[0], &cameras[1]}) {
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

// The vector env's render without Python: N heads of the env's scene drawn by one
// Renderer::RenderBatch call into one buffer (N stereo observations). Each head shows the
// scene's first `objects` objects (3, or 0: the ground and the sky alone) in front of it,
// shifted sideways by its index, and turns at its own rate, so no two heads see the same
// image. Arguments: N, RendererOptions::batch_contexts (0: automatic), objects.
// `stereo_obs_per_s` is N x calls a second (bench/baselines/python-env-2core.md; on a GPU the
// figure of issue 17's N = 256).
void BM_RenderBatch(benchmark::State& bench) {
  const std::optional<saccade::scene::Scene> env = EnvScene(bench);
  if (!env) return;
  const saccade::scene::Scene& scene = *env;
  auto renderer = EnvRenderer(scene, static_cast<int>(bench.range(1)));
  const auto& head = scene.robot()->head;
  const int w = scene.cameras()[0].model.intrinsics().width();
  const int h = scene.cameras()[0].model.intrinsics().height();
  const int count = static_cast<int>(bench.range(0));
  const std::size_t shown = static_cast<std::size_t>(bench.range(2));
  std::vector<uint8_t> out(static_cast<std::size_t>(count) * 2 * w * h * 3);
  std::vector<saccade::render::BatchHead> heads(count);
  const std::size_t n = scene.objects().size();
  const Eigen::Vector3d base = head.X_WB().translation();
  for (int k = 0; k < count; ++k) {
    heads[k].object_poses.resize(n);
    heads[k].hidden.assign(n, true);
    for (std::size_t i = 0; i < std::min(shown, n); ++i) {
      heads[k].hidden[i] = false;
      saccade::geometry::Pose X = saccade::geometry::Pose::Identity();
      X.translation() = base + Eigen::Vector3d(2.0, -0.6 + 0.6 * i + 0.01 * (k % 17), 0.0);
      X.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      heads[k].object_poses[i] = X;
    }
  }
  const double dt = 0.04;
  int64_t step = 0;
  const auto pose = [&](int k) {
    JointState joints = head.Home();
    const auto& pan = head.joint(0).limits;
    joints[0] = std::clamp(0.002 * (k % 64) * static_cast<double>(step % 100), pan.min, pan.max);
    return joints;
  };
  for (int k = 0; k < count; ++k) heads[k].state.joints = pose(k);
  renderer->RenderBatch(heads, out.data(), out.size());  // the tiles' framebuffer, untimed
  const saccade::render::RenderStats before = renderer->stats();
  for (auto _ : bench) {
    ++step;
    for (int k = 0; k < count; ++k) {
      heads[k].state.time = static_cast<double>(step) * dt;
      heads[k].state.joints = pose(k);
    }
    renderer->RenderBatch(heads, out.data(), out.size());
    benchmark::DoNotOptimize(out.data());
  }
  bench.counters["stereo_obs_per_s"] = benchmark::Counter(
      static_cast<double>(bench.iterations()) * count, benchmark::Counter::kIsRate);
  // Where a call's time goes (RenderStats; with two contexts, the sum of both threads'): the
  // draw calls issued (on llvmpipe, rasterised too), and waiting for and converting the pixels.
  const saccade::render::RenderStats& after = renderer->stats();
  const double calls = static_cast<double>(std::max<int64_t>(1, bench.iterations()));
  bench.counters["draw_ms"] = (after.draw_ms - before.draw_ms) / calls;
  bench.counters["readback_ms"] = (after.readback_ms - before.readback_ms) / calls;
}
BENCHMARK(BM_RenderBatch)
    ->ArgNames({"N", "contexts", "objects"})
    ->Args({1, 0, 3})
    ->Args({16, 0, 3})
    ->Args({64, 0, 3})
    ->Args({256, 0, 3})
    ->Args({256, 0, 0})
    ->Args({256, 1, 3})
    ->Args({256, 2, 3})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
