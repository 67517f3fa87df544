// A component's declared parameter ranges and its library's Options::IsValid come from the
// same Interval (core/interval.h), so that they cannot disagree (issue 46, item 2): every value
// at, inside and just outside each bound gets the same verdict from both, and a pipeline file's
// value outside the range is refused naming the file, line, component and parameter.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/runtime/component_registry.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/resources.h"
#include "saccade/vision/camshift_tracker.h"
#include "saccade/vision/face_detector.h"
#include "saccade/vision/inhibition_of_return.h"
#include "saccade/vision/median_filter.h"
#include "saccade/vision/sharpener.h"
#include "saccade/vision/stereo_associator.h"
#include "saccade/vision/undistorter.h"

namespace saccade::components {
namespace {

using nlohmann::json;
using Options = vision::FaceDetector::Options;

const std::string kScene = std::string(SACCADE_SOURCE_DIR) + "/scenes/astronaut_and_cat.yaml";

// Whether the component `type` accepts `params` (its declared ranges, then what Configured
// checks across parameters, which it leaves to its library by constructing it).
bool ComponentAccepts(const std::string& type, const json& params) {
  RegisterComponents();
  // Shared, as a pipeline's components share them: the scene is loaded once.
  static const auto resources =
      std::make_shared<runtime::Resources>(runtime::ComponentRegistry::Global().resource_loaders());
  std::unique_ptr<runtime::Component> c = runtime::ComponentRegistry::Global().Create(type);
  c->Initialise(type, 1, {}, resources);
  try {
    c->Configure(params);
  } catch (const InvalidArgument&) {
    return false;
  }
  return true;
}

// One parameter: how it sets the library's Options, and the values to try (around each bound).
template <typename O>
struct Case {
  std::string param;
  std::function<void(O&, double)> set;
  std::vector<double> values;
  bool integer;
};

struct Verdicts {
  int accepted = 0, refused = 0;
};

// For each case's values: the component `type` (given `fixed` besides the value) and `base`
// with the value set (the Options the component starts from) give the same verdict.
template <typename O>
Verdicts ExpectAgreement(const std::string& type, const json& fixed, const O& base,
                         const std::vector<Case<O>>& cases) {
  Verdicts verdicts;
  for (const Case<O>& c : cases) {
    for (double v : c.values) {
      O options = base;
      c.set(options, v);
      std::string why;
      const bool library = options.IsValid(&why);
      const json value = c.integer ? json(static_cast<int>(v)) : json(v);
      json params = fixed;
      params[c.param] = value;
      const bool component = ComponentAccepts(type, params);
      EXPECT_EQ(component, library) << type << ": " << c.param << " = " << value.dump()
                                    << ": library says " << (library ? "valid" : why);
      (library ? verdicts.accepted : verdicts.refused) += 1;
    }
  }
  return verdicts;
}

// The next double above / below `x`.
double Up(double x) { return std::nextafter(x, std::numeric_limits<double>::infinity()); }
double Down(double x) { return std::nextafter(x, -std::numeric_limits<double>::infinity()); }

TEST(ParamAgreement, TheFaceDetectorComponentAndItsLibraryGiveTheSameVerdictOnEveryValue) {
  const std::vector<Case<Options>> cases = {
      {"pyramid_level",
       [](Options& o, double v) { o.pyramid_level = static_cast<int>(v); },
       {-1, 0, 1, 4, 5},
       true},
      {"scale_factor",
       [](Options& o, double v) { o.scale_factor = v; },
       {0.5, 1.0, Up(1.0), 1.0001, 1.1, 4.0, Up(4.0), 100},
       false},
      {"min_neighbors",
       [](Options& o, double v) { o.min_neighbors = static_cast<int>(v); },
       {-1, 0, 3, 1000, 1001},
       true},
      {"min_size_px",
       [](Options& o, double v) { o.min_size_px = static_cast<int>(v); },
       {0, 1, 30, 100000, 100001},
       true},
      // 0 is no limit; otherwise at least min_size_px (30 by default): a check across two
      // parameters, which the component runs through the library's IsValid.
      {"max_size_px",
       [](Options& o, double v) { o.max_size_px = static_cast<int>(v); },
       {-1, 0, 1, 29, 30, 100000, 100001},
       true},
  };
  // One cascade to load: the verdict is about the numbers.
  const Verdicts v = ExpectAgreement<Options>(
      "vision.face_detector", {{"reject_cats", false}, {"require_eyes", false}}, {}, cases);
  // Both verdicts occur: the values straddle the bounds.
  EXPECT_GE(v.refused, 10);
  EXPECT_GE(v.accepted, 15);
}

TEST(ParamAgreement, TheCamShiftComponentAndItsLibraryGiveTheSameVerdictOnEveryValue) {
  using O = vision::CamShiftTracker::Options;
  const std::vector<Case<O>> cases = {
      {"min_mass_ratio",
       [](O& o, double v) { o.min_mass_ratio = v; },
       {-0.1, Down(0.0), 0.0, 0.3, 0.999, Down(1.0), 1.0, 1.5},
       false},
  };
  const Verdicts v = ExpectAgreement<O>("vision.camshift", {{"eye", "left"}}, {}, cases);
  EXPECT_GE(v.refused, 4);
  EXPECT_GE(v.accepted, 4);
}

TEST(ParamAgreement, TheSharpenComponentAndItsLibraryGiveTheSameVerdictOnEveryValue) {
  using O = vision::Sharpener::Options;
  const std::vector<Case<O>> cases = {
      {"amount",
       [](O& o, double v) { o.amount = v; },
       {-1.0, Down(0.0), 0.0, 1.0, 100.0, Up(100.0), 101.0},
       false},
      {"sigma",
       [](O& o, double v) { o.sigma = v; },
       {-1.0, 0.0, 1e-9, 1e-6, 1.0, 50.0, Up(50.0), 51.0},
       false},
  };
  const Verdicts v = ExpectAgreement<O>("vision.sharpen", json::object(), {}, cases);
  EXPECT_GE(v.refused, 7);
  EXPECT_GE(v.accepted, 7);
}

TEST(ParamAgreement, TheMedianComponentAndItsLibraryGiveTheSameVerdictOnEveryValue) {
  using O = vision::MedianFilter::Options;
  // Even sizes inside [3, 255] are refused by the library's second check, which the
  // component runs by constructing the filter.
  const std::vector<Case<O>> cases = {
      {"kernel_size",
       [](O& o, double v) { o.kernel_size = static_cast<int>(v); },
       {-3, 1, 2, 3, 4, 5, 253, 254, 255, 256, 257},
       true},
  };
  const Verdicts v = ExpectAgreement<O>("vision.median", json::object(), {}, cases);
  EXPECT_GE(v.refused, 7);
  EXPECT_GE(v.accepted, 4);
}

TEST(ParamAgreement, TheAttentionComponentAndItsLibraryGiveTheSameVerdictOnEveryValue) {
  using O = vision::InhibitionOfReturn::Options;
  O base;
  base.suppression_time_s = 60.0;  // the component's default
  const std::vector<Case<O>> cases = {
      {"fixation_time_s",
       [](O& o, double v) { o.fixation_time_s = v; },
       {-1.0, 0.0, 1e-9, 2.0, 1e6, Up(1e6), 2e6},
       false},
      {"radius_m",
       [](O& o, double v) { o.radius_m = v; },
       {-1.0, 0.0, 1e-9, 0.15, 1e6, Up(1e6), 2e6},
       false},
      {"suppression_time_s",
       [](O& o, double v) { o.suppression_time_s = v; },
       {-1.0, 0.0, 1e-9, 60.0, 1e9, Up(1e9), 2e9},
       false},
  };
  const Verdicts v = ExpectAgreement<O>("vision.attention", {{"scene", kScene}}, base, cases);
  EXPECT_GE(v.refused, 12);
  EXPECT_GE(v.accepted, 9);
}

TEST(ParamAgreement, TheStereoFacesComponentAndItsLibraryGiveTheSameVerdictOnEveryValue) {
  using O = vision::StereoAssociator::Options;
  O base;  // the component's defaults: a human face's width, refined disparity
  base.min_width_m = 0.08;
  base.max_width_m = 0.4;
  base.refine_disparity = true;
  const std::vector<Case<O>> cases = {
      {"max_reprojection_px",
       [](O& o, double v) { o.max_reprojection_px = v; },
       {-1.0, 0.0, 1e-9, 4.0, 1e6, Up(1e6)},
       false},
      // Against max_depth_m (20): at or above it is refused by the check across the two.
      {"min_depth_m",
       [](O& o, double v) { o.min_depth_m = v; },
       {-1.0, 0.0, 1e-9, 0.1, Down(20.0), 20.0, 1e6, Up(1e6)},
       false},
      {"max_depth_m",
       [](O& o, double v) { o.max_depth_m = v; },
       {0.0, 0.05, 0.1, Up(0.1), 20.0, 1e6, Up(1e6)},
       false},
      // Against max_width_m (0.4).
      {"min_width_m",
       [](O& o, double v) { o.min_width_m = v; },
       {-0.1, Down(0.0), 0.0, 0.08, Down(0.4), 0.4, 1e6, Up(1e6)},
       false},
      // Against min_width_m (0.08): 0 turns the check off only with min_width_m 0.
      {"max_width_m",
       [](O& o, double v) { o.max_width_m = v; },
       {-0.1, 0.0, 0.08, Up(0.08), 0.4, 1e6, Up(1e6)},
       false},
  };
  const Verdicts v = ExpectAgreement<O>("vision.stereo_faces", json::object(), base, cases);
  EXPECT_GE(v.refused, 18);
  EXPECT_GE(v.accepted, 14);
}

TEST(ParamAgreement, TheUndistortComponentAndItsLibraryGiveTheSameVerdictOnEveryValue) {
  using O = vision::Undistorter::Options;
  const std::vector<Case<O>> cases = {
      {"border_value",
       [](O& o, double v) { o.border_value = static_cast<int>(v); },
       {-1, 0, 128, 255, 256},
       true},
  };
  const Verdicts v = ExpectAgreement<O>("vision.undistort", json::object(), {}, cases);
  EXPECT_GE(v.refused, 2);
  EXPECT_GE(v.accepted, 3);
}

TEST(ParamAgreement, AnOpenBoundIsWrittenOpenAndRefusedWithTheFileLineAndKey) {
  RegisterComponents();
  const std::string file = std::string(SACCADE_SOURCE_DIR) + "/pipelines/bad.yaml";
  std::string message = "accepted";
  try {
    runtime::Pipeline::LoadString(
        "clock: {mode: simulated, step: 0.04, steps: 1}\ncomponents:\n"
        "  - {name: d, type: vision.face_detector, params: {scale_factor: 1.0}}\n",
        file);
  } catch (const Error& e) {
    message = e.what();
  }
  EXPECT_EQ(message, file +
                         ":3: components[0].params: component 'd' (vision.face_detector): "
                         "parameter 'scale_factor': expected a number in (1, 4], got 1.0");
  // The library says the same of the same value, in its own words.
  Options options;
  options.scale_factor = 1.0;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_EQ(why, "FaceDetector::Options: scale_factor 1, expected (1, 4]");
}

}  // namespace
}  // namespace saccade::components
