// A component's declared parameter ranges and its library's Options::IsValid come from the
// same Interval (core/interval.h), so that they cannot disagree (issue 46, item 2): every value
// at, inside and just outside each bound gets the same verdict from both, and a pipeline file's
// value outside the range is refused naming the file, line, component and parameter.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "saccade/components/register.h"
#include "saccade/core/error.h"
#include "saccade/runtime/component_registry.h"
#include "saccade/runtime/pipeline.h"
#include "saccade/runtime/resources.h"
#include "saccade/vision/face_detector.h"

namespace saccade::components {
namespace {

using nlohmann::json;
using Options = vision::FaceDetector::Options;

// Whether vision.face_detector accepts `params` (its declared ranges, then what Configured
// checks across parameters).
bool ComponentAccepts(const json& params) {
  RegisterComponents();
  auto resources =
      std::make_shared<runtime::Resources>(runtime::ComponentRegistry::Global().resource_loaders());
  std::unique_ptr<runtime::Component> c =
      runtime::ComponentRegistry::Global().Create("vision.face_detector");
  c->Initialise("vision.face_detector", 1, {}, resources);
  json all = params;
  all["reject_cats"] = false;  // one cascade to load: the verdict is about the numbers
  all["require_eyes"] = false;
  try {
    c->Configure(all);
  } catch (const InvalidArgument&) {
    return false;
  }
  return true;
}

struct Case {
  std::string param;
  std::function<void(Options&, double)> set;
  std::vector<double> values;  // around each bound
  bool integer;
};

TEST(ParamAgreement, TheFaceDetectorComponentAndItsLibraryGiveTheSameVerdictOnEveryValue) {
  const double up = std::nextafter(1.0, 2.0) - 1.0;  // the step above 1
  const std::vector<Case> cases = {
      {"pyramid_level",
       [](Options& o, double v) { o.pyramid_level = static_cast<int>(v); },
       {-1, 0, 1, 4, 5},
       true},
      {"scale_factor",
       [](Options& o, double v) { o.scale_factor = v; },
       {0.5, 1.0, 1.0 + up, 1.0001, 1.1, 4.0, 4.0 + 4 * up, 100},
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
  int refused = 0, accepted = 0;
  for (const Case& c : cases) {
    for (double v : c.values) {
      Options options;
      c.set(options, v);
      std::string why;
      const bool library = options.IsValid(&why);
      const json value = c.integer ? json(static_cast<int>(v)) : json(v);
      const bool component = ComponentAccepts({{c.param, value}});
      EXPECT_EQ(component, library)
          << c.param << " = " << value.dump() << ": library says " << (library ? "valid" : why);
      (library ? accepted : refused) += 1;
    }
  }
  // Both verdicts occur: the values straddle the bounds.
  EXPECT_GE(refused, 10);
  EXPECT_GE(accepted, 15);
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
