// The demo as a module (components/demo/demo_session.h): its options, the pipelines it refuses,
// a short run with its recording and summary, and a live run that a front end paces and stops.
#include "saccade/components/demo/demo_session.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "scene/scene_test_util.h"

namespace saccade::components::demo {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

const std::string kSource = SACCADE_SOURCE_DIR;

DemoOptions Demo(double duration) {
  RegisterComponents();
  DemoOptions options;
  options.pipeline = kSource + "/pipelines/demo.yaml";
  options.duration = duration;
  return options;
}

TEST(DemoOptions, ADurationThatIsNotPositiveAndFiniteIsRefusedNamingIt) {
  std::string error;
  EXPECT_TRUE(Demo(40.0).IsValid(&error));
  for (const double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    EXPECT_FALSE(Demo(bad).IsValid(&error)) << bad;
    EXPECT_THAT(error, StartsWith("demo: --duration must be > 0 s, got ")) << bad;
  }
  EXPECT_THROW(DemoSession(Demo(-1.0), {}), InvalidArgument);
}

TEST(DemoSession, APipelineWithoutEyeCamerasIsRefusedNamingTheFile) {
  const scene::testing::TempDir dir;
  const fs::path file = dir.Write("head_only.yaml", "scene: " + kSource +
                                                        "/scenes/portraits.yaml\n"
                                                        "clock: {mode: simulated, step: 0.04}\n"
                                                        "components:\n"
                                                        "  - name: head\n"
                                                        "    type: sim.head\n");
  DemoOptions options = Demo(1.0);
  options.pipeline = file.string();
  try {
    DemoSession session(options, {});
    FAIL() << "no error";
  } catch (const InvalidArgument& e) {
    EXPECT_EQ(std::string(e.what()),
              "demo: pipeline " + file.string() +
                  " has no eye cameras (a sim.cameras, hw.cameras or remote.cameras component)");
  }
}

// Ten steps of pipelines/demo.yaml, recorded: a frame per step, and summary.json is the
// summary's JSON form.
TEST(DemoSession, AShortRunRecordsEveryStepAndSummarisesIt) {
  const scene::testing::TempDir dir;
  DemoOptions options = Demo(0.4);  // 10 steps of 0.04 s
  options.record = (dir.path() / "recording").string();
  std::vector<std::string> lines;
  DemoSession session(options, [&](const std::string& line) { lines.push_back(line); });
  std::atomic<bool> stop{false};
  const DemoSummary summary = session.Run(stop, {});

  EXPECT_EQ(summary.run.steps, 10);
  EXPECT_TRUE(summary.truth);
  EXPECT_EQ(summary.faces_total, 3);  // scenes/portraits.yaml: three portraits and the cat
  EXPECT_FALSE(summary.nothing_ran());
  EXPECT_EQ(summary.recorded_frames, 10);
  EXPECT_TRUE(fs::exists(dir.path() / "recording" / "frames" / "000009.jpg"));
  EXPECT_TRUE(fs::exists(dir.path() / "recording" / "demo.avi"));
  std::ifstream file(dir.path() / "recording" / "summary.json");
  EXPECT_EQ(json::parse(file), summary.Json());
  EXPECT_EQ(summary.Json()["record"]["frames"], 10);
  EXPECT_EQ(summary.Json()["steps"], 10);

  EXPECT_THAT(summary.BriefReport(),
              StartsWith(std::to_string(summary.faces_fixated) + " of 3 faces fixated in 0.40 s"));
  EXPECT_THAT(summary.FullReport(), StartsWith("\n" + summary.BriefReport() + "\n"));
  EXPECT_THAT(summary.FullReport(), HasSubstr("recorded to " + options.record));
  // A line for each fixation as it arrived.
  int fixated = 0;
  for (const Fixation& f : summary.fixations) fixated += f.fixated_at ? 1 : 0;
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(fixated));
  if (fixated > 0) {
    EXPECT_THAT(lines[0], HasSubstr("fixated " + summary.fixations[0].object));
  }

  // The recording is not replaced unless asked.
  EXPECT_THROW(DemoSession(options, {}).Run(stop, {}), InvalidArgument);
}

// Live (the browser GUI): the loop runs with no step limit, the front end sees every step and
// stops it; the summary says it was interrupted.
TEST(DemoSession, ALiveRunGoesOnUntilTheFrontEndStopsIt) {
  DemoOptions options = Demo(0.04);  // not a limit when live
  options.live = true;
  DemoSession session(options, {});
  int steps_seen = 0;
  RunHooks hooks;
  std::atomic<bool> stop{false};
  hooks.after_step = [&](const runtime::StepContext& context, const Latest& latest,
                         const std::atomic<bool>& stop_seen) {
    EXPECT_EQ(&stop_seen, &stop);
    EXPECT_EQ(context.step, steps_seen);
    EXPECT_TRUE(latest.joints.has_value());
    if (++steps_seen == 4) stop = true;
  };
  const DemoSummary summary = session.Run(stop, hooks);
  EXPECT_EQ(steps_seen, 4);
  EXPECT_EQ(summary.run.steps, 4);
  EXPECT_TRUE(summary.interrupted);
}

}  // namespace
}  // namespace saccade::components::demo
