// sim.cameras' raw mosaic (`raw: true`, issue 45): each camera with a colour filter array gets
// an output <camera>_raw carrying the Bayer mosaic its colour image was demosaiced from, checked
// against OpenCV's demosaicing; a scene with no filter array is refused naming the parameter and
// the cameras; the demo's and the GUI's latest image of a camera stays its colour image. Small
// images: each test well under a second.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "saccade/components/demo/loop_outputs.h"
#include "saccade/components/register.h"
#include "saccade/components/roles.h"
#include "saccade/core/error.h"
#include "saccade/core/image.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/scheduler.h"
#include "scratch_dir.h"

namespace saccade::components {
namespace {

// Two colour cameras behind an RGGB filter (linear tone curve: the image is the plain
// demosaicing of the mosaic) and one without a filter, before a coloured checker and a box.
const std::string kScene = R"(
background: [0.3, 0.5, 0.9]
lights: [{type: ambient, intensity: 0.6}, {type: directional, direction: [1, 0.3, -1], intensity: 0.6}]
ground: {pattern: checker, cell: 0.2, color: [0.9, 0.5, 0.2], color2: [0.1, 0.3, 0.8]}
objects:
  - {name: box, kind: box, size: 0.5, color: [0.2, 0.8, 0.4, 1], pose: {position: [2, 0, 0.25]}}
cameras:
  - name: eye
    calibration: {width: 160, height: 120, fx: 120, fy: 120}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
    sensor: {exposure_ms: 8, blur_samples: 1, read_noise_dn: 1, seed: 3,
             color: {cfa: rggb, white_balance: {red: 1.3, blue: 1.6}}}
  - name: plain
    calibration: {width: 80, height: 60, fx: 60, fy: 60}
    look_at: {eye: [0, 0.2, 1], target: [2, 0, 0.3]}
)";

std::string ScenePath() {
  const std::string path = (testing_helpers::ScratchDir() / "raw_scene.yaml").string();
  std::ofstream(path) << kScene;
  return path;
}

std::string Pipeline(const std::string& cameras, bool raw) {
  return "clock: {mode: simulated, step: 0.04, steps: 2}\n"
         "components:\n"
         "  - name: cams\n"
         "    type: sim.cameras\n"
         "    params: {scene: " +
         ScenePath() + ", cameras: " + cameras + ", raw: " + (raw ? "true" : "false") + "}\n";
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

TEST(SimCamerasRaw, EachFilteredCameraEmitsTheMosaicItsImageWasDemosaicedFrom) {
  RegisterComponents();
  runtime::Pipeline pipeline =
      runtime::Pipeline::LoadString(Pipeline("[eye, plain]", true), "raw.yaml");
  const runtime::Component& cams = *pipeline.components().at(0);
  std::vector<std::string> outputs;
  for (const auto& output : cams.outputs()) outputs.push_back(output->name());
  // A camera without a filter has no mosaic: no raw output.
  EXPECT_EQ(outputs, (std::vector<std::string>{"eye", "plain", "eye_raw"}));
  const auto* role = dynamic_cast<const EyeCamerasRole*>(&cams);
  ASSERT_NE(role, nullptr);
  EXPECT_EQ(role->RawMosaicCamera("eye_raw"), "eye");
  EXPECT_EQ(role->RawMosaicCamera("eye"), "");

  std::map<std::string, std::vector<std::shared_ptr<const Image>>> got;  // by output
  for (const auto& output : cams.outputs()) {
    auto* typed = dynamic_cast<runtime::Output<runtime::ImageMessage>*>(output.get());
    ASSERT_NE(typed, nullptr);
    typed->signal().Connect([&got, name = output->name()](const runtime::ImageMessage& m) {
      got[name].push_back(m.image);
    });
  }
  demo::Latest latest;  // what the demo's report and the GUI show of each camera
  demo::TapLoopOutputs(pipeline, &latest);
  const runtime::RunSummary summary = runtime::RunPipeline(pipeline);
  ASSERT_EQ(summary.errors_total, 0) << summary.FullReport();
  ASSERT_EQ(got["eye"].size(), 2u);
  // The mosaic carries its camera's name too; the camera's latest image stays the colour one.
  ASSERT_TRUE(latest.images["eye"]);
  EXPECT_EQ(latest.images["eye"], got["eye"].back());
  ASSERT_EQ(got["eye_raw"].size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    SCOPED_TRACE(i);
    const Image& color = *got["eye"][i];
    const Image& raw = *got["eye_raw"][i];
    EXPECT_EQ(raw.format(), PixelFormat::kBayerRggb8);
    EXPECT_EQ(raw.width(), 160);
    EXPECT_EQ(raw.height(), 120);
    // The colour image's metadata, the camera controls included.
    const ImageMetadata& a = color.metadata();
    const ImageMetadata& b = raw.metadata();
    EXPECT_EQ(b.camera, "eye");
    EXPECT_EQ(b.frame_index, a.frame_index);
    EXPECT_EQ(b.time, a.time);
    EXPECT_EQ(b.exposure_s, 0.008);
    EXPECT_EQ(b.exposure_s, a.exposure_s);
    EXPECT_EQ(b.gain_db, a.gain_db);
    EXPECT_EQ(b.focus_m, a.focus_m);
    // With a linear tone curve the colour image is OpenCV's demosaicing of the mosaic, bit for
    // bit (tests/render/camera_chain_test.cc): RGGB is OpenCV's BayerBG, bilinear its plain code.
    const cv::Mat mosaic(raw.height(), raw.width(), CV_8UC1, const_cast<uint8_t*>(raw.data()),
                         raw.stride());
    cv::Mat rgb;
    cv::demosaicing(mosaic, rgb, cv::COLOR_BayerBG2RGB);
    ASSERT_EQ(color.format(), PixelFormat::kRgb8);
    bool same = true;
    for (int y = 0; y < color.height() && same; ++y) {
      same =
          std::memcmp(color.row(y), rgb.ptr(y), static_cast<std::size_t>(color.width()) * 3) == 0;
    }
    EXPECT_TRUE(same) << "the colour image is not cv::demosaicing of the raw mosaic";
    // The mosaic is not a grey rendering: R sites of the green box are darker than G sites.
    EXPECT_NE(std::memcmp(raw.row(60), raw.row(61), 160), 0);
  }
  // Without `raw`, no raw output (the default).
  runtime::Pipeline off =
      runtime::Pipeline::LoadString(Pipeline("[eye, plain]", false), "off.yaml");
  EXPECT_EQ(off.components().at(0)->outputs().size(), 2u);
}

TEST(SimCamerasRaw, RawOfCamerasWithoutAFilterArrayNamesTheParameterAndTheCameras) {
  RegisterComponents();
  const std::string error =
      ErrorOf([] { runtime::Pipeline::LoadString(Pipeline("[plain]", true), "no_cfa.yaml"); });
  EXPECT_NE(error.find("component 'cams' (sim.cameras)"), std::string::npos) << error;
  EXPECT_NE(error.find("parameter 'raw': no camera of 'cameras' (plain) in scene '" + ScenePath() +
                       "' has a colour filter array"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("cfa: rggb"), std::string::npos) << error;
}

}  // namespace
}  // namespace saccade::components
