// A camera's photometric chain in the renderer (issue 45; render/camera_chain.h): the colour
// filter's frames against the library's pipeline and against cv::demosaicing of the raw
// mosaic, cos^4 vignetting on a flat white field against the formula, the legacy noise after
// the lens bit for bit as before, the depth of field of an edge in and out of focus against
// the thin lens's circle of confusion, and its depth from the colour pass against the truth's.
// Small images: each test well under a second or two.

#include "saccade/render/camera_chain.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "saccade/core/image.h"
#include "saccade/core/image_io.h"
#include "saccade/render/color_filter.h"
#include "saccade/render/dataset.h"
#include "saccade/render/lens_optics.h"
#include "saccade/render/renderer.h"
#include "saccade/render/sensor_model.h"
#include "saccade/scene/scene.h"
#include "scratch_dir.h"

namespace saccade::render {
namespace {

scene::Scene SceneFrom(const std::string& yaml) {
  return scene::Scene::FromYamlString(yaml, "camera_chain_test.yaml",
                                      std::filesystem::path(SACCADE_SOURCE_DIR) / "scenes");
}

std::vector<Frame> RenderOnce(const scene::Scene& world, const RendererOptions& options = {}) {
  std::unique_ptr<Renderer> renderer = MakeRenderer(world, options);
  return renderer->Render(world.InitialState(), 0);
}

bool SamePixels(const ImageView& a, const ImageView& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.format() != b.format()) return false;
  const std::size_t row = static_cast<std::size_t>(a.width()) * BytesPerPixel(a.format());
  for (int y = 0; y < a.height(); ++y) {
    if (std::memcmp(a.row(y), b.row(y), row) != 0) return false;
  }
  return true;
}

// A coloured checker ground and a green box, seen by cameras with a colour filter.
const std::string kColourScene = R"(
background: [0.3, 0.5, 0.9]
lights: [{type: ambient, intensity: 0.6}, {type: directional, direction: [1, 0.3, -1], intensity: 0.6}]
ground: {pattern: checker, cell: 0.2, color: [0.9, 0.5, 0.2], color2: [0.1, 0.3, 0.8]}
objects:
  - {name: box, kind: box, size: 0.5, color: [0.2, 0.8, 0.4, 1], pose: {position: [2, 0, 0.25]}}
cameras:
  - name: srgb
    calibration: {width: 160, height: 120, fx: 120, fy: 120}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
    sensor: {color: {cfa: rggb, white_balance: {red: 1.3, blue: 1.6}, tone_curve: srgb}}
  - name: linear
    calibration: {width: 161, height: 121, fx: 120, fy: 120,
                  distortion: {model: radtan, coefficients: [-0.2, 0.05, 0, 0, 0]}}
    look_at: {eye: [0, 0.2, 1], target: [2, 0, 0.3]}
    sensor: {read_noise_dn: 2, gain_dn_per_e: 0.2, seed: 3,
             color: {cfa: gbrg, demosaic: edge_aware, white_balance: {green: 0.9}}}
  - name: tone_only
    calibration: {width: 160, height: 120, fx: 120, fy: 120}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
    sensor: {color: {tone_curve: {gamma: 2.2}}}
)";

TEST(CameraChain, ColourFramesAreTheLibrarysPipelineOfThePlainFrames) {
  const scene::Scene world = SceneFrom(kColourScene);
  RendererOptions plain_options;
  plain_options.color = false;
  const std::vector<Frame> frames = RenderOnce(world);
  const std::vector<Frame> plain = RenderOnce(world, plain_options);
  ASSERT_EQ(frames.size(), 3u);
  ASSERT_EQ(plain.size(), 3u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const scene::CameraSpec& camera = *world.FindCamera(frames[i].color->metadata().camera);
    EXPECT_EQ(plain[i].raw, nullptr) << camera.name << ": color off gives no mosaic";
    const ColorImages expected =
        ApplyColorPipeline(plain[i].color->view(), ToColorOptions(camera.sensor.color));
    EXPECT_TRUE(SamePixels(frames[i].color->view(), expected.rgb.view())) << camera.name;
    if (camera.sensor.color.cfa == CfaPattern::kNone) {
      EXPECT_EQ(frames[i].raw, nullptr) << camera.name;
      continue;
    }
    ASSERT_NE(frames[i].raw, nullptr) << camera.name;
    EXPECT_EQ(frames[i].raw->format(), BayerFormat(camera.sensor.color.cfa)) << camera.name;
    EXPECT_EQ(frames[i].raw->metadata().camera, camera.name);
    EXPECT_EQ(frames[i].raw->metadata().frame_index, 0);
    EXPECT_TRUE(SamePixels(frames[i].raw->view(), expected.raw.view())) << camera.name;
    // The plain frame is not the coloured one (the effect is on).
    EXPECT_FALSE(SamePixels(frames[i].color->view(), plain[i].color->view())) << camera.name;
  }
  // With a linear tone curve the image is OpenCV's demosaicing of the raw mosaic: gbrg is
  // OpenCV's BayerGR, edge-aware its _EA code.
  const Frame& linear = frames[1];
  ASSERT_EQ(linear.color->metadata().camera, "linear");
  const Image& raw = *linear.raw;
  const cv::Mat mosaic(raw.height(), raw.width(), CV_8UC1, const_cast<uint8_t*>(raw.data()),
                       raw.stride());
  cv::Mat rgb;
  cv::demosaicing(mosaic, rgb, cv::COLOR_BayerGR2RGB_EA);
  const ImageView opencv(rgb.data, rgb.cols, rgb.rows, PixelFormat::kRgb8, rgb.step);
  EXPECT_TRUE(SamePixels(linear.color->view(), opencv));
}

// A Bayer camera with an EMVA sensor exposes its mosaic, a photosite a pixel (one value, not
// three): the raw mosaic is a 1-channel SensorModel's exposure of the plain frame's mosaic, white
// balanced, bit for bit, and the image is cv::demosaicing of it.
TEST(CameraChain, AnEmvaSensorBehindAColourFilterExposesTheMosaic) {
  const scene::Scene world = SceneFrom(R"(
background: [0.3, 0.5, 0.9]
lights: [{type: ambient, intensity: 0.6}, {type: directional, direction: [1, 0.3, -1], intensity: 0.6}]
ground: {pattern: checker, cell: 0.2, color: [0.9, 0.5, 0.2], color2: [0.1, 0.3, 0.8]}
cameras:
  - name: bayer
    calibration: {width: 160, height: 120, fx: 120, fy: 120}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
    sensor: {exposure_ms: 8, seed: 5, emva: {preset: imx174},
             color: {cfa: bggr, white_balance: {red: 1.25, blue: 1.5}}}
)");
  RendererOptions plain_options;
  plain_options.color = false;
  plain_options.noise = false;
  const std::vector<Frame> frames = RenderOnce(world);
  const std::vector<Frame> plain = RenderOnce(world, plain_options);
  ASSERT_NE(frames[0].raw, nullptr);
  const scene::CameraSpec& camera = *world.FindCamera("bayer");
  Image expected = Mosaic(plain[0].color->view(), CfaPattern::kBggr);
  const SensorModel sensor(*camera.sensor.emva, camera.sensor.seed, camera.name, 160, 120, 1);
  sensor.ExposeRendered(expected.view(), camera.sensor.exposure, 0, &expected);
  ApplyWhiteBalanceToMosaic(expected, ToColorOptions(camera.sensor.color).white_balance);
  EXPECT_TRUE(SamePixels(frames[0].raw->view(), expected.view()));
  // Not the noiseless mosaic: the sensor's noise is in it.
  Image noiseless = Mosaic(plain[0].color->view(), CfaPattern::kBggr);
  ApplyWhiteBalanceToMosaic(noiseless, ToColorOptions(camera.sensor.color).white_balance);
  EXPECT_FALSE(SamePixels(frames[0].raw->view(), noiseless.view()));
  const cv::Mat mosaic(120, 160, CV_8UC1, const_cast<uint8_t*>(frames[0].raw->data()),
                       frames[0].raw->stride());
  cv::Mat rgb;
  cv::demosaicing(mosaic, rgb, cv::COLOR_BayerRG2RGB);  // bggr is OpenCV's BayerRG
  EXPECT_TRUE(SamePixels(frames[0].color->view(),
                         ImageView(rgb.data, 160, 120, PixelFormat::kRgb8, rgb.step)));
}

// The realistic chain whole (vignetting, depth of field, a Bayer EMVA sensor): the renderer
// gathers the depth of field for each photosite's own colour only, straight into the mosaic;
// the raw mosaic is still the library's functions one after the other, bit for bit: the plain
// frame vignetted, blurred by its truth depth, mosaiced, exposed and white balanced.
TEST(CameraChain, TheDepthOfFieldOfABayerSensorIsTheMosaicOfTheBlurredImage) {
  const scene::Scene world = SceneFrom(R"(
background: [0.3, 0.5, 0.9]
lights: [{type: ambient, intensity: 0.6}, {type: directional, direction: [1, 0.3, -1], intensity: 0.6}]
ground: {pattern: checker, cell: 0.2, color: [0.9, 0.5, 0.2], color2: [0.1, 0.3, 0.8]}
objects:
  - {name: box, kind: box, size: 0.1, color: [0.2, 0.8, 0.4, 1], pose: {position: [0.8, 0.05, 0.72]}}
cameras:
  - name: bayer
    calibration: {width: 161, height: 120, fx: 400, fy: 400}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
    sensor: {exposure_ms: 8, seed: 5, emva: {preset: imx174},
             color: {cfa: grbg, white_balance: {red: 1.25, blue: 1.5}}}
    lens: {vignetting: cos4, f_number: 1, focal_length_mm: 16, focus_distance: 3, max_coc_px: 8}
)");
  RendererOptions with_depth, plain_options;
  with_depth.truth_depth = plain_options.truth_depth = true;
  plain_options.color = plain_options.noise = plain_options.optics = false;
  const std::vector<Frame> frames = RenderOnce(world, with_depth);
  const std::vector<Frame> plain = RenderOnce(world, plain_options);
  ASSERT_NE(frames[0].raw, nullptr);
  ASSERT_NE(plain[0].depth, nullptr);
  const scene::CameraSpec& camera = *world.FindCamera("bayer");
  Image vignetted = *plain[0].color;
  ApplyVignetting(vignetted, VignettingFactors(camera.model, ToVignettingOptions(camera.lens)));
  DepthOfFieldSummary summary;
  const Image blurred =
      ApplyDepthOfField(vignetted.view(), plain[0].depth->view(),
                        ToThinLensOptions(camera.lens, camera.lens.focus_distance_m),
                        camera.model.intrinsics(), &summary);
  EXPECT_GT(summary.max_coc_px, 4.0);  // the box at 0.8 m, 3 m from the focus: blurred
  Image expected = Mosaic(blurred.view(), CfaPattern::kGrbg);
  const SensorModel sensor(*camera.sensor.emva, camera.sensor.seed, camera.name, 161, 120, 1);
  sensor.ExposeRendered(expected.view(), camera.sensor.exposure, 0, &expected);
  ApplyWhiteBalanceToMosaic(expected, ToColorOptions(camera.sensor.color).white_balance);
  EXPECT_TRUE(SamePixels(frames[0].raw->view(), expected.view()));
  // The blur is in it: the mosaic of the sharp image differs.
  Image sharp = Mosaic(vignetted.view(), CfaPattern::kGrbg);
  sensor.ExposeRendered(sharp.view(), camera.sensor.exposure, 0, &sharp);
  ApplyWhiteBalanceToMosaic(sharp, ToColorOptions(camera.sensor.color).white_balance);
  EXPECT_FALSE(SamePixels(frames[0].raw->view(), sharp.view()));
}

TEST(CameraChain, TheDataSetHoldsTheRawMosaicAndItsPattern) {
  const scene::Scene world = SceneFrom(kColourScene);
  const std::vector<Frame> frames = RenderOnce(world);
  const std::filesystem::path out = testing_helpers::ScratchDir() / "set";
  {
    DatasetWriter writer(world, {"srgb", "linear", "tone_only"}, TruthRequest{}, out, false, true);
    writer.Write(0, 0.0, world.InitialState(), frames);
  }
  // 8-bit single-channel PNGs of the mosaic's bytes, for the cameras with a filter.
  const Image raw = ReadImage(out / "srgb/raw/000000.png");
  EXPECT_EQ(raw.format(), PixelFormat::kGray8);
  const Image& expected = *frames[0].raw;
  ASSERT_EQ(raw.width(), expected.width());
  for (int y = 0; y < raw.height(); ++y) {
    ASSERT_EQ(std::memcmp(raw.row(y), expected.row(y), raw.width()), 0) << y;
  }
  EXPECT_TRUE(std::filesystem::exists(out / "linear/raw/000000.png"));
  EXPECT_FALSE(std::filesystem::exists(out / "tone_only/raw"));
  std::ifstream index(out / "frames.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(index, line));
  EXPECT_NE(line.find(R"("cfa":"rggb")"), std::string::npos) << line;
  EXPECT_NE(line.find(R"("cfa":"gbrg")"), std::string::npos) << line;
  EXPECT_NE(line.find(R"("raw":"srgb/raw/000000.png")"), std::string::npos) << line;
}

// A camera that sees only a white sky (255), with the given lens and sensor keys.
std::string WhiteField(const std::string& keys) {
  return R"(
background: [1, 1, 1]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
cameras:
  - name: flat
    calibration: {width: 160, height: 120, fx: 90, fy: 100, cx: 81.3, cy: 58.2}
    pose: {position: [0, 0, 1]}
)" + keys +
         "\n";
}

TEST(CameraChain, Cos4VignettingDarkensAFlatFieldAsTheFormula) {
  const scene::Scene world = SceneFrom(WhiteField("    lens: {vignetting: cos4}"));
  const std::vector<Frame> frames = RenderOnce(world);
  const Image& image = *frames[0].color;
  const geometry::Intrinsics& K = world.FindCamera("flat")->model.intrinsics();
  // Every pixel within half a DN (the rounding) of 255 cos^4(theta), theta its ray's angle.
  double worst = 0.0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const double u = (x - K.cx()) / K.fx(), v = (y - K.cy()) / K.fy();
      const double cos2 = 1.0 / (1.0 + u * u + v * v);
      const double expected = 255.0 * cos2 * cos2;
      for (int c = 0; c < 3; ++c) {
        worst = std::max(worst, std::abs(image.row(y)[3 * x + c] - expected));
      }
    }
  }
  EXPECT_LE(worst, 0.5 + 1e-4) << "DN off 255 cos^4";
  // The corners are visibly dark: about 0.21 of the centre at (0, 119).
  EXPECT_LT(image.row(119)[0], 90);
  EXPECT_EQ(image.row(58)[3 * 81], 255);
  // Off (RendererOptions::optics): the plain white field.
  RendererOptions off;
  off.optics = false;
  const std::vector<Frame> plain = RenderOnce(world, off);
  EXPECT_EQ(plain[0].color->row(119)[0], 255);
}

TEST(CameraChain, NoiseAfterTheLensIsTheLegacyNoiseBitForBit) {
  // A vignetting of factor 1 everywhere moves the noise after the lens, on the CPU: the same
  // bits as the noise fused with the readback (or drawn in the final pass).
  const std::string sensor = "    sensor: {read_noise_dn: 3, gain_dn_per_e: 0.5, seed: 9}\n";
  const scene::Scene before = SceneFrom(WhiteField(sensor));
  const scene::Scene after =
      SceneFrom(WhiteField(sensor + "    lens: {vignetting: {polynomial: [0, 0, 0]}}"));
  const std::vector<Frame> frames_before = RenderOnce(before);
  const std::vector<Frame> frames_after = RenderOnce(after);
  const Image& a = *frames_before[0].color;
  const Image& b = *frames_after[0].color;
  EXPECT_TRUE(SamePixels(a.view(), b.view()));
  // And the noise is there: not the plain white field.
  int below = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < 3 * a.width(); ++x) below += a.row(y)[x] < 255;
  }
  EXPECT_GT(below, a.width() * a.height());
}

// Two cameras of one thin lens focused at 1 m: one sees a white box's vertical edge at 1 m, the
// other one at 3 m, both on a black sky.
const std::string kDepthOfField = R"(
background: [0, 0, 0]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
objects:
  - {name: near, kind: box, size: [2, 0.01, 2], color: [1, 1, 1, 1], pose: {position: [1, 1.005, 0]}}
  - {name: far, kind: box, size: [2, 0.01, 2], color: [1, 1, 1, 1], pose: {position: [11, 3.005, 0]}}
cameras:
  - name: near
    calibration: {width: 240, height: 80, fx: 800, fy: 800, cx: 119.5, cy: 39.5}
    look_at: {eye: [0, 0, 0], target: [0, 1, 0]}
    lens: &lens {f_number: 1, focal_length_mm: 16, focus_distance: 1, max_coc_px: 24}
  - name: far
    calibration: {width: 240, height: 80, fx: 800, fy: 800, cx: 119.5, cy: 39.5}
    look_at: {eye: [10, 0, 0], target: [10, 1, 0]}
    lens: *lens
)";

// The 10-90 % width (pixels) of the edge across row `y`'s green channel.
double EdgeWidth(const Image& image, int y) {
  std::vector<double> v(image.width());
  for (int x = 0; x < image.width(); ++x) v[x] = image.row(y)[3 * x + 1];
  const double lo = *std::min_element(v.begin(), v.end());
  const double hi = *std::max_element(v.begin(), v.end());
  const bool rising = v.back() > v.front();
  // The crossing of `level` (interpolated between pixels), from the dark side.
  const auto crossing = [&](double level) {
    for (int x = 0; x + 1 < image.width(); ++x) {
      const double a = rising ? v[x] : v[image.width() - 1 - x];
      const double b = rising ? v[x + 1] : v[image.width() - 2 - x];
      if (a < level && b >= level) return x + (level - a) / (b - a);
    }
    return 0.0;
  };
  return crossing(lo + 0.9 * (hi - lo)) - crossing(lo + 0.1 * (hi - lo));
}

TEST(CameraChain, DepthOfFieldKeepsTheFocusSharpAndBlursByTheCircleOfConfusion) {
  const scene::Scene world = SceneFrom(kDepthOfField);
  RendererOptions sharp_options;
  sharp_options.optics = false;
  const std::vector<Frame> frames = RenderOnce(world);
  const std::vector<Frame> sharp = RenderOnce(world, sharp_options);
  ASSERT_EQ(frames.size(), 2u);
  // The depth is drawn for the lens, not returned unless asked.
  EXPECT_EQ(frames[0].depth, nullptr);
  const scene::CameraSpec& camera = *world.FindCamera("far");
  const ThinLensOptions lens = ToThinLensOptions(camera.lens, camera.lens.focus_distance_m);
  const int row = 40;
  // In focus (1 m): the edge as sharp as without the lens (within a tenth of a pixel).
  const double near_width = EdgeWidth(*frames[0].color, row);
  EXPECT_NEAR(near_width, EdgeWidth(*sharp[0].color, row), 0.1);
  // At 3 m: a disc's edge, 10-90 % over 0.687 of its diameter.
  const double coc = CircleOfConfusionPx(lens, camera.model.intrinsics(), 3.0);
  const double far_width = EdgeWidth(*frames[1].color, row);
  std::cout << "edge at the focus: " << near_width << " px (without the lens "
            << EdgeWidth(*sharp[0].color, row) << "); at 3 m: " << far_width
            << " px 10-90 %, a disc of " << far_width / 0.687 << " px against the formula's " << coc
            << " px\n";
  EXPECT_GT(coc, 8.0);
  EXPECT_NEAR(far_width / 0.687 / coc, 1.0, 0.10)
      << "edge 10-90 % " << far_width << " px, circle " << coc << " px";
  EXPECT_LT(EdgeWidth(*sharp[1].color, row), 1.5);
  // Asked for, the depth comes back as truth.
  RendererOptions truth;
  truth.truth_depth = true;
  const std::vector<Frame> with_depth = RenderOnce(world, truth);
  ASSERT_NE(with_depth[1].depth, nullptr);
  EXPECT_TRUE(SamePixels(with_depth[1].color->view(), frames[1].color->view()));
}

// A commanded focus distance (scene::SceneState::camera_controls, as camera.accommodation sends
// it) replaces the lens's for that frame: both cameras focused at 3 m, the far edge is as sharp
// as without the lens and the near one blurs by the circle of confusion of 1 m seen from 3 m.
TEST(CameraChain, ACommandedFocusDistanceMovesTheDepthOfField) {
  const scene::Scene world = SceneFrom(kDepthOfField);
  scene::SceneState state = world.InitialState();
  state.camera_controls["near"].focus_m = 3.0;
  state.camera_controls["far"].focus_m = 3.0;
  std::unique_ptr<Renderer> renderer = MakeRenderer(world, {});
  const std::vector<Frame> frames = renderer->Render(state, 0);
  RendererOptions sharp_options;
  sharp_options.optics = false;
  const std::vector<Frame> sharp = RenderOnce(world, sharp_options);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_DOUBLE_EQ(frames[0].color->metadata().focus_m, 3.0);
  const int row = 40;
  EXPECT_NEAR(EdgeWidth(*frames[1].color, row), EdgeWidth(*sharp[1].color, row), 0.1);
  const scene::CameraSpec& camera = *world.FindCamera("near");
  const double coc =
      CircleOfConfusionPx(ToThinLensOptions(camera.lens, 3.0), camera.model.intrinsics(), 1.0);
  EXPECT_GT(coc, 8.0);
  EXPECT_NEAR(EdgeWidth(*frames[0].color, row) / 0.687 / coc, 1.0, 0.10);
  // Without a command the frame says the lens's own focus distance.
  EXPECT_DOUBLE_EQ(sharp[0].color->metadata().focus_m, 1.0);
}

// A distorted camera with a strong depth of field over a checker floor from 0.4 m to the
// horizon and boxes at 0.7, 1.5 and 4 m. Without ground truth asked, a software rasteriser's
// renderer takes the depth of field's depth from the colour pass's depth buffer, remapped
// through the lens on the CPU (render/gl/internal_color_depth.h); asked for the depth, from the
// truth pass and its remap on the GPU. The two depths differ in float rounding and at the
// edges' interpolation only: the images agree within a DN but for a few pixels at the edges.
const std::string kDepthOfFieldDistorted = R"(
background: [0.5, 0.7, 0.9]
lights: [{type: ambient, intensity: 0.5}, {type: directional, direction: [1, 0.3, -1], intensity: 0.6}]
ground: {pattern: checker, cell: 0.1, color: [0.95, 0.9, 0.8], color2: [0.1, 0.15, 0.2]}
objects:
  - {name: a, kind: box, size: 0.1, color: [0.9, 0.2, 0.2, 1], pose: {position: [0.7, 0.1, 0.4]}}
  - {name: b, kind: box, size: 0.3, color: [0.2, 0.9, 0.2, 1], pose: {position: [1.5, -0.3, 0.3]}}
  - {name: c, kind: box, size: 0.8, color: [0.2, 0.2, 0.9, 1], pose: {position: [4, 0.6, 0.4]}}
cameras:
  - name: eye
    calibration: {width: 320, height: 240, fx: 260, fy: 260, cx: 159.5, cy: 119.5,
                  distortion: {model: radtan, coefficients: [-0.25, 0.08, 0.001, -0.0005, 0]}}
    look_at: {eye: [0, 0, 0.6], target: [2, 0, 0.2]}
    lens: {vignetting: cos4, f_number: 1.4, focal_length_mm: 4, focus_distance: 1.5,
           pixel_pitch_um: 3, max_coc_px: 12}
)";

TEST(CameraChain, TheColourPassDepthBlursAsTheTruthPassDepth) {
  const scene::Scene world = SceneFrom(kDepthOfFieldDistorted);
  RendererOptions colour_depth, truth_depth;
  colour_depth.lens_on_cpu = truth_depth.lens_on_cpu = true;
  truth_depth.truth_depth = true;
  const std::vector<Frame> a = RenderOnce(world, colour_depth);
  const std::vector<Frame> b = RenderOnce(world, truth_depth);
  ASSERT_EQ(a[0].depth, nullptr);
  ASSERT_NE(b[0].depth, nullptr);
  const Image& x = *a[0].color;
  const Image& y = *b[0].color;
  ASSERT_EQ(x.width(), y.width());
  int differing = 0, beyond_one = 0, largest = 0;
  for (int r = 0; r < x.height(); ++r) {
    for (int c = 0; c < 3 * x.width(); ++c) {
      const int d = std::abs(x.row(r)[c] - y.row(r)[c]);
      differing += d != 0;
      beyond_one += d > 1;
      largest = std::max(largest, d);
    }
  }
  const int values = 3 * x.width() * x.height();
  std::cout << "colour-pass depth against truth-pass depth: " << differing << " of " << values
            << " values differ, " << beyond_one << " by more than 1 DN, at most " << largest
            << " DN\n";
  // The blur is there (the near box and the floor's near checkers), and the same.
  RendererOptions sharp = colour_depth;
  sharp.optics = false;
  const std::vector<Frame> plain = RenderOnce(world, sharp);
  int blurred = 0;
  for (int r = 0; r < x.height(); ++r) {
    for (int c = 0; c < 3 * x.width(); ++c)
      blurred += std::abs(x.row(r)[c] - plain[0].color->row(r)[c]) > 8;
  }
  EXPECT_GT(blurred, values / 20);
  EXPECT_LT(differing, values / 1000);
  EXPECT_LT(beyond_one, values / 10000);
}

}  // namespace
}  // namespace saccade::render
