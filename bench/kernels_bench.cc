// Kernel benchmarks (Google Benchmark): the per-point and per-solve costs of the camera model
// and the head kinematics. Whole-program figures come from `saccade bench` (later issues).
//   build/bin/kernels_bench [--benchmark_filter=Project]

#include <benchmark/benchmark.h>

#include <opencv2/calib3d.hpp>
#include <random>
#include <vector>

#include "saccade/geometry/camera_model.h"
#include "saccade/geometry/lens_map.h"
#include "saccade/head/head_description.h"
#include "saccade/head/kinematics.h"

namespace {

using saccade::geometry::CameraModel;
using saccade::geometry::Distortion;
using saccade::geometry::Intrinsics;

const Intrinsics kIntrinsics(1024, 768, 1290.3, 1288.1, 515.2, 380.7, 0.0);
const std::vector<double> kRadTan = {-0.28, 0.09, 0.001, -0.0005, -0.012};
const std::vector<double> kFisheye = {0.05, -0.01, 0.002, -0.0003};

std::vector<Eigen::Vector3d> Points(int n) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> xy(-0.35, 0.35), z(1.0, 3.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) {
    const double depth = z(rng);
    points.emplace_back(xy(rng) * depth, xy(rng) * depth, depth);
  }
  return points;
}

void BM_ProjectRadTan(benchmark::State& state) {
  const CameraModel camera(kIntrinsics, Distortion::RadialTangential(kRadTan));
  const auto points = Points(1024);
  for (auto _ : state) {
    for (const auto& p : points) benchmark::DoNotOptimize(camera.Project(p));
  }
  state.SetItemsProcessed(state.iterations() * points.size());
}
BENCHMARK(BM_ProjectRadTan);

void BM_OpenCvProjectPoints(benchmark::State& state) {
  // The same work through cv::projectPoints, for the ratio.
  const auto points = Points(1024);
  std::vector<cv::Point3d> cv_points;
  for (const auto& p : points) cv_points.emplace_back(p.x(), p.y(), p.z());
  const cv::Matx33d K(kIntrinsics.fx(), 0, kIntrinsics.cx(), 0, kIntrinsics.fy(), kIntrinsics.cy(),
                      0, 0, 1);
  std::vector<cv::Point2d> pixels;
  for (auto _ : state) {
    cv::projectPoints(cv_points, cv::Vec3d::zeros(), cv::Vec3d::zeros(), K, kRadTan, pixels);
    benchmark::DoNotOptimize(pixels.data());
  }
  state.SetItemsProcessed(state.iterations() * points.size());
}
BENCHMARK(BM_OpenCvProjectPoints);

void BM_UnprojectRadTan(benchmark::State& state) {
  const CameraModel camera(kIntrinsics, Distortion::RadialTangential(kRadTan));
  std::vector<Eigen::Vector2d> pixels;
  for (const auto& p : Points(1024)) pixels.push_back(*camera.Project(p));
  for (auto _ : state) {
    for (const auto& uv : pixels) benchmark::DoNotOptimize(camera.Unproject(uv));
  }
  state.SetItemsProcessed(state.iterations() * pixels.size());
}
BENCHMARK(BM_UnprojectRadTan);

void BM_UnprojectFisheye(benchmark::State& state) {
  const CameraModel camera(kIntrinsics, Distortion::Fisheye(kFisheye));
  std::vector<Eigen::Vector2d> pixels;
  for (const auto& p : Points(1024)) pixels.push_back(*camera.Project(p));
  for (auto _ : state) {
    for (const auto& uv : pixels) benchmark::DoNotOptimize(camera.Unproject(uv));
  }
  state.SetItemsProcessed(state.iterations() * pixels.size());
}
BENCHMARK(BM_UnprojectFisheye);

void BM_MakeLensMapRadTan(benchmark::State& state) {
  // Strong barrel at 1024 x 768 (one wider pinhole view): one undistortion per pixel.
  const CameraModel camera(
      Intrinsics(1024, 768, 800.0, 795.0, 517.3, 379.6),
      Distortion::RadialTangential(std::vector<double>{-0.35, 0.12, 0.001, -0.0015, -0.02}));
  for (auto _ : state) benchmark::DoNotOptimize(saccade::geometry::MakeLensMap(camera).map.data());
  state.SetItemsProcessed(state.iterations() * 1024 * 768);
}
BENCHMARK(BM_MakeLensMapRadTan)->Unit(benchmark::kMillisecond);

void BM_MakeLensMapFisheye190(benchmark::State& state) {
  // 190 degrees across a 1280 x 960 image (five cube faces).
  const std::vector<double> k = {-0.01, 0.002, -0.0003, 0.00002};
  const double theta = 95.0 * 3.14159265358979323846 / 180.0, t2 = theta * theta;
  const double f = 641.3 / (theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])))));
  const CameraModel camera(Intrinsics(1280, 960, f, 0.997 * f, 641.3, 478.9, 0.8),
                           Distortion::Fisheye(k));
  for (auto _ : state) benchmark::DoNotOptimize(saccade::geometry::MakeLensMap(camera).map.data());
  state.SetItemsProcessed(state.iterations() * 1280 * 960);
}
BENCHMARK(BM_MakeLensMapFisheye190)->Unit(benchmark::kMillisecond);

void BM_SolveFixation(benchmark::State& state) {
  const auto head = saccade::head::HeadDescription::FromYamlFile(std::string(SACCADE_SOURCE_DIR) +
                                                                 "/robots/popeye.yaml");
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> x(1.0, 3.0), yz(-0.5, 0.5);
  std::vector<Eigen::Vector3d> targets;
  for (int i = 0; i < 256; ++i)
    targets.push_back(head.X_WB() * Eigen::Vector3d(x(rng), yz(rng), yz(rng)));
  for (auto _ : state) {
    for (const auto& t : targets) benchmark::DoNotOptimize(saccade::head::SolveFixation(head, t));
  }
  state.SetItemsProcessed(state.iterations() * targets.size());
}
BENCHMARK(BM_SolveFixation);

}  // namespace

BENCHMARK_MAIN();
