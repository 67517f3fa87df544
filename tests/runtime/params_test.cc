// Declared parameters (params.h): a component declares each parameter once, and its parsing
// (with the pipeline file's line in errors), its --list-components entry and its line in
// docs/components.md all come from that one declaration.

#include "saccade/runtime/params.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/runtime/component_reference.h"
#include "saccade/runtime/pipeline.h"

namespace saccade::runtime {
namespace {

using ::testing::HasSubstr;
using json = nlohmann::json;

// A component with three parameters, each declared once.
class Blur final : public Component {
 public:
  Blur() {
    DeclareParam("sigma", &sigma, "Gaussian's standard deviation").Range(0.1, 20.0).Unit("px");
    DeclareParam("passes", &passes, "how many times it is applied").Range(1, 5);
    DeclareParam("border", &border, "how the image is extended").Choices({"clamp", "mirror"});
  }
  void Step(const StepContext&) override {}
  int configured = 0;
  double sigma = 1.5;
  int passes = 1;
  std::string border = "clamp";

 protected:
  void Configured() override { ++configured; }
};

std::string ErrorOf(Component& component, const json& params) {
  try {
    component.Configure(params);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(Params, DefaultsAreTheMembersValuesAndGivenValuesSetTheMembers) {
  Blur blur;
  blur.Configure(nullptr);
  EXPECT_EQ(blur.sigma, 1.5);
  EXPECT_EQ(blur.passes, 1);
  EXPECT_EQ(blur.border, "clamp");
  EXPECT_EQ(blur.configured, 1);
  blur.Configure({{"sigma", 3}, {"passes", 4}, {"border", "mirror"}});
  EXPECT_EQ(blur.sigma, 3.0);
  EXPECT_EQ(blur.passes, 4);
  EXPECT_EQ(blur.border, "mirror");
  // Configured again without them: back to the declared defaults.
  blur.Configure(json::object());
  EXPECT_EQ(blur.sigma, 1.5);
  EXPECT_EQ(blur.passes, 1);
  EXPECT_EQ(blur.border, "clamp");
}

TEST(Params, BadValuesNameTheParameterAndChangeNothing) {
  Blur blur;
  EXPECT_EQ(ErrorOf(blur, {{"sigma", 0.0}}),
            "parameter 'sigma': expected a number in [0.1, 20], got 0.0");
  EXPECT_EQ(ErrorOf(blur, {{"sigma", "wide"}}),
            "parameter 'sigma': expected a number in [0.1, 20], got \"wide\"");
  EXPECT_EQ(ErrorOf(blur, {{"passes", 2.5}}),
            "parameter 'passes': expected an integer in [1, 5], got 2.5");
  EXPECT_EQ(ErrorOf(blur, {{"passes", 6}}),
            "parameter 'passes': expected an integer in [1, 5], got 6");
  EXPECT_EQ(ErrorOf(blur, {{"border", "wrap"}}),
            "parameter 'border': expected one of clamp, mirror, got 'wrap'");
  EXPECT_EQ(ErrorOf(blur, {{"sigmaa", 2}}),
            "unknown parameter 'sigmaa' (known: border, passes, sigma)");
  EXPECT_EQ(ErrorOf(blur, json::array()), "params: expected a mapping of parameters, got []");
  // A good value beside a bad one is not applied either, and Configured is not called.
  EXPECT_EQ(ErrorOf(blur, {{"sigma", 5.0}, {"passes", 0}}),
            "parameter 'passes': expected an integer in [1, 5], got 0");
  EXPECT_EQ(blur.sigma, 1.5);
  EXPECT_EQ(blur.configured, 0);
}

// Ranges taken from a library's Interval: open ends stay open on numbers, and become the
// nearest integers inside on integers; unbounded ends are unbounded.
class Ranged final : public Component {
 public:
  Ranged() {
    DeclareParam("ratio", &ratio, "a step above 1").Range(Interval::LeftOpen(1, 4));
    DeclareParam("gap", &gap, "below 1").Range(Interval::RightOpen(-1, 1));
    DeclareParam("count", &count, "above 1, at most 4").Range(Interval::LeftOpen(1, 4));
    DeclareParam("level", &level, "fractional ends").Range(Interval::RightOpen(0.5, 3.5));
    DeclareParam("many", &many, "at least 2").Range(Interval::AtLeast(2));
  }
  void Step(const StepContext&) override {}
  double ratio = 2, gap = 0;
  int count = 2, level = 1, many = 2;
};

TEST(Params, IntervalRangesKeepOpenEndsOnNumbersAndRoundIntegerEndsInside) {
  Ranged r;
  EXPECT_EQ(ErrorOf(r, {{"ratio", 1}}), "parameter 'ratio': expected a number in (1, 4], got 1");
  EXPECT_EQ(ErrorOf(r, {{"ratio", 1.000001}}), "accepted");
  EXPECT_EQ(ErrorOf(r, {{"ratio", 4}}), "accepted");
  EXPECT_EQ(ErrorOf(r, {{"gap", 1}}), "parameter 'gap': expected a number in [-1, 1), got 1");
  EXPECT_EQ(ErrorOf(r, {{"gap", -1}}), "accepted");
  EXPECT_EQ(ErrorOf(r, {{"count", 1}}), "parameter 'count': expected an integer in [2, 4], got 1");
  EXPECT_EQ(ErrorOf(r, {{"count", 4}}), "accepted");
  EXPECT_EQ(ErrorOf(r, {{"level", 0}}), "parameter 'level': expected an integer in [1, 3], got 0");
  EXPECT_EQ(ErrorOf(r, {{"level", 3}}), "accepted");
  EXPECT_EQ(ErrorOf(r, {{"many", 1}}), "parameter 'many': expected an integer in [2, inf], got 1");
  EXPECT_EQ(ErrorOf(r, {{"many", 2000000000}}), "accepted");
  // The interval's own text and verdict, as a library's IsValid uses them.
  EXPECT_EQ(Interval::LeftOpen(1, 4).Text(), "(1, 4]");
  EXPECT_EQ(Interval::AtLeast(0.5).Text(), "[0.5, inf)");
  EXPECT_FALSE(Interval::Closed(0, 1).Contains(std::nan("")));
  EXPECT_FALSE(Interval::AtLeast(0).Contains(std::numeric_limits<double>::infinity()));
  EXPECT_TRUE(Interval::AtLeast(0).Contains(1e308));
}

TEST(Params, IntegersBeyondTheMembersTypeAreRefused) {
  struct Wide final : Component {
    Wide() { DeclareParam("n", &n, "an int without a range"); }
    void Step(const StepContext&) override {}
    int n = 0;
  } wide;
  EXPECT_EQ(ErrorOf(wide, {{"n", int64_t{1} << 40}}),
            "parameter 'n': expected an integer, got 1099511627776");
  EXPECT_EQ(ErrorOf(wide, {{"n", -7}}), "accepted");
  EXPECT_EQ(wide.n, -7);
}

TEST(Params, RequiredParametersAndDeclarationMistakes) {
  struct Needs final : Component {
    Needs() { DeclareParam("eye", &eye, "which eye").Choices({"left", "right"}).Required(); }
    void Step(const StepContext&) override {}
    std::string eye;
  } needs;
  EXPECT_EQ(ErrorOf(needs, json::object()),
            "parameter 'eye' is required: one of left, right (which eye)");
  EXPECT_EQ(ErrorOf(needs, {{"eye", "right"}}), "accepted");
  EXPECT_EQ(needs.eye, "right");

  ParamTable table;
  double x = 0.0;
  table.Declare("x", &x, "");
  EXPECT_THROW(table.Declare("x", &x, ""), InvalidArgument);
  EXPECT_THROW(table.Declare("not a name", &x, ""), InvalidArgument);
}

// In a pipeline file, the loader adds the file, the line and the component.
TEST(Params, PipelineErrorsNameTheFileAndLine) {
  ComponentRegistry registry;
  registry.Register<Blur>("test.blur", "blurs");
  try {
    Pipeline::LoadString(
        "clock: {mode: simulated, step: 0.1, steps: 1}\n"
        "components:\n"
        "  - name: b\n"
        "    type: test.blur\n"
        "    params: {sigma: 40}\n",
        "blur.yaml", registry);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "blur.yaml:5: components[0].params: component 'b' (test.blur): parameter 'sigma': "
              "expected a number in [0.1, 20], got 40");
  }
}

// The --list-components entry and the docs/components.md table rows come from the same
// declaration as the parsing above.
TEST(Params, ReferenceTextJsonAndMarkdownComeFromTheDeclaration) {
  ComponentRegistry registry;
  registry.Register<Blur>("test.blur", "blurs an image");
  const std::vector<ComponentReference> reference = DescribeComponents(registry);
  ASSERT_EQ(reference.size(), 1u);
  ASSERT_EQ(reference[0].params.size(), 3u);

  const std::string text = ComponentsText(reference);
  EXPECT_THAT(text, HasSubstr("test.blur -- blurs an image\n  params:\n"));
  EXPECT_THAT(text,
              HasSubstr("    sigma   number in [0.1, 20] px, default 1.5: Gaussian's standard "
                        "deviation\n"));
  EXPECT_THAT(text, HasSubstr("    passes  integer in [1, 5], default 1: how many times it is "
                              "applied\n"));
  EXPECT_THAT(text, HasSubstr("    border  one of clamp, mirror, default \"clamp\": how the "
                              "image is extended\n"));

  const std::string markdown = ComponentsMarkdown(reference);
  EXPECT_THAT(markdown, HasSubstr("## test.blur\n\nblurs an image.\n"));
  EXPECT_THAT(markdown, HasSubstr("| `sigma` | number in [0.1, 20] | `1.5` | px | Gaussian's "
                                  "standard deviation |\n"));
  EXPECT_THAT(markdown, HasSubstr("| `passes` | integer in [1, 5] | `1` |  | how many times it "
                                  "is applied |\n"));
  EXPECT_THAT(markdown, HasSubstr("| `border` | one of clamp, mirror | `\"clamp\"` |  | how the "
                                  "image is extended |\n"));

  const json j = ComponentsJson(reference);
  const json& sigma = j[0]["params"][0];
  EXPECT_EQ(sigma["name"], "sigma");
  EXPECT_EQ(sigma["default"], 1.5);
  EXPECT_EQ(sigma["min"], 0.1);
  EXPECT_EQ(sigma["max"], 20.0);
  EXPECT_EQ(sigma["unit"], "px");
  EXPECT_EQ(j[0]["params"][2]["choices"], json({"clamp", "mirror"}));
}

}  // namespace
}  // namespace saccade::runtime
