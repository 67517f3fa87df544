// Kinematics of every shipped head (issue 42): forward kinematics of all links, a camera's
// Jacobian, and the fixation solve, per head. The solve runs over 1,000 fixed targets that the
// head can fixate (0.5-4 m ahead, within 25 degrees), each from the previous solution as a
// tracking loop does, and from home; POPEYE's appendix-A solvers are timed beside them.
// Baselines: bench/baselines/head-2core.md.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <filesystem>
#include <random>

#include "saccade/head/fixation.h"
#include "saccade/head/kinematics.h"

namespace saccade::head {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

const char* const kHeads[] = {"popeye", "popeye_urdf", "humanoid", "pan_tilt_vergence",
                              "pan_tilt_fixed"};

HeadModel Load(int index) {
  return HeadModel::FromFile(fs::path(SACCADE_SOURCE_DIR) / "robots" /
                             (std::string(kHeads[index]) + ".yaml"));
}

std::vector<Vector3d> Targets(const HeadModel& head) {
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vector3d> targets;
  while (targets.size() < 1000) {
    const double distance = 0.5 + 3.5 * unit(random);
    const double azimuth = (unit(random) - 0.5) * 50 * M_PI / 180;
    const double elevation = (unit(random) - 0.5) * 50 * M_PI / 180;
    const Vector3d p_B =
        distance * Vector3d(std::cos(elevation) * std::cos(azimuth),
                            std::cos(elevation) * std::sin(azimuth), std::sin(elevation)) +
        Vector3d(0, 0, 0.2);
    targets.push_back(head.X_WB() * p_B);
  }
  return targets;
}

void BM_ForwardKinematics(benchmark::State& state) {
  const HeadModel head = Load(static_cast<int>(state.range(0)));
  state.SetLabel(kHeads[state.range(0)]);
  std::vector<geometry::Pose> X_WL;
  Eigen::VectorXd q = head.HomePosture();
  for (auto _ : state) {
    q[0] += 1e-9;
    head.ForwardKinematics(q, &X_WL);
    benchmark::DoNotOptimize(X_WL.data());
  }
}
BENCHMARK(BM_ForwardKinematics)->DenseRange(0, 4);

void BM_CameraJacobian(benchmark::State& state) {
  const HeadModel head = Load(static_cast<int>(state.range(0)));
  state.SetLabel(kHeads[state.range(0)]);
  std::vector<geometry::Pose> X_WL;
  head.ForwardKinematics(head.HomePosture(), &X_WL);
  Eigen::Matrix<double, 6, Eigen::Dynamic> J;
  const int link = head.camera(0).link;
  for (auto _ : state) {
    head.tree().Jacobian(X_WL, link, X_WL[link].translation(), &J);
    benchmark::DoNotOptimize(J.data());
  }
}
BENCHMARK(BM_CameraJacobian)->DenseRange(0, 4);

// range(1): 0 = from the previous solution (tracking), 1 = from home.
void BM_Fixation(benchmark::State& state) {
  const HeadModel head = Load(static_cast<int>(state.range(0)));
  const bool from_home = state.range(1) == 1;
  state.SetLabel(fmt::format("{}, {}", kHeads[state.range(0)], from_home ? "home" : "tracking"));
  const std::vector<Vector3d> targets = Targets(head);
  FixationSolver solver(head);
  FixationOptions options;
  options.seed = head.HomePosture();
  size_t i = 0;
  int failures = 0;
  for (auto _ : state) {
    const FixationResult result = solver.Solve(targets[i++ % targets.size()], options);
    failures += !result.reachable();
    if (!from_home && result.reachable()) options.seed = result.joints;
  }
  state.counters["unreachable"] = failures;
}
BENCHMARK(BM_Fixation)->ArgsProduct({{0, 1, 2, 3, 4}, {0, 1}})->Unit(benchmark::kMicrosecond);

void BM_PopeyeAppendixA(benchmark::State& state) {
  const HeadDescription head =
      HeadDescription::FromYamlFile(fs::path(SACCADE_SOURCE_DIR) / "robots/popeye.yaml");
  const std::vector<Vector3d> targets = Targets(HeadModel::FromDescription(head));
  const bool closed_form = state.range(0) == 0;
  state.SetLabel(closed_form ? "closed form (eqs. 10-13)" : "Newton (kinematics.h)");
  size_t i = 0;
  for (auto _ : state) {
    const Vector3d& p = targets[i++ % targets.size()];
    const IkResult result = closed_form ? SolveFixationClosedForm(head, p) : SolveFixation(head, p);
    benchmark::DoNotOptimize(result.joints.pan);
  }
}
BENCHMARK(BM_PopeyeAppendixA)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace saccade::head

BENCHMARK_MAIN();
