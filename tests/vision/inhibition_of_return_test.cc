// Inhibition of return (seed section 7.2): the closest target is selected until it has been
// fixated for fixation_time_s; then it is suppressed for suppression_time_s and the next
// closest is selected, so the head visits every target in turn.
#include "saccade/vision/inhibition_of_return.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::vision {
namespace {

using Eigen::Vector3d;

const Vector3d kViewer(0, 0, 1.2);
// The scene's portraits: the astronaut at 2.2 m, the cat at 3 m, and a third face at 4 m.
const std::vector<Vector3d> kTargets = {{3.0, -0.55, 1.15}, {2.2, 0.4, 1.25}, {4.0, 1.0, 1.2}};

// Simulates a head that fixates whatever was selected on the previous step (with a few mm of
// triangulation noise) at 30 Hz, and returns the sequence of distinct selections.
std::vector<std::size_t> Visits(InhibitionOfReturn& ior, double duration_s) {
  std::vector<std::size_t> visits;
  std::optional<Vector3d> fixation;
  for (int i = 0; i * (1.0 / 30.0) < duration_s; ++i) {
    const double t = i / 30.0;
    std::vector<Vector3d> seen = kTargets;
    for (Vector3d& p : seen) p += Vector3d(0.003 * ((i % 3) - 1), 0.0, 0.002 * ((i % 2)));
    const std::optional<std::size_t> pick = ior.Select(t, seen, kViewer, fixation);
    if (pick && (visits.empty() || visits.back() != *pick)) visits.push_back(*pick);
    fixation = pick ? std::optional<Vector3d>(seen[*pick]) : std::nullopt;
  }
  return visits;
}

TEST(InhibitionOfReturn, VisitsEveryTargetInTurnClosestFirst) {
  InhibitionOfReturn::Options options;
  options.fixation_time_s = 1.0;
  options.suppression_time_s = 10.0;
  InhibitionOfReturn ior(options);
  // 0 .. 1 s the astronaut (closest), 1 .. 2 s the cat, 2 .. 3 s the far face; then all three
  // are suppressed (nothing selected) until the astronaut's suppression ends at 11 s.
  EXPECT_EQ(Visits(ior, 3.5), (std::vector<std::size_t>{1, 0, 2}));
}

// Two faces walking across the view at 0.1 m/s (0.4 m over the run, more than radius_m): the
// nearer (0) is fixated for a second, pursued and let go, then the farther (1). Does attention
// come back to the first once it has left the place where it was let go?
std::vector<std::size_t> MovingVisits(bool follow) {
  InhibitionOfReturn::Options options;
  options.fixation_time_s = 1.0;
  options.suppression_time_s = 60.0;
  options.radius_m = 0.15;
  options.follow = follow;
  InhibitionOfReturn ior(options);
  std::vector<std::size_t> visits;
  std::optional<Vector3d> fixation;
  for (int i = 0; i < 120; ++i) {  // 4 s
    const double t = i / 30.0;
    const std::vector<Vector3d> seen = {Vector3d(2.0, -0.6 + 0.1 * t, 1.2),
                                        Vector3d(3.0, 0.6 - 0.1 * t, 1.2)};
    const std::optional<std::size_t> pick = ior.Select(t, seen, kViewer, fixation);
    if (pick && (visits.empty() || visits.back() != *pick)) visits.push_back(*pick);
    fixation = pick ? std::optional<Vector3d>(seen[*pick]) : std::nullopt;
  }
  return visits;
}

TEST(InhibitionOfReturn, SuppressionFollowsAMovingFace) {
  // Following: each face once; then both stay suppressed wherever they go.
  EXPECT_EQ(MovingVisits(true), (std::vector<std::size_t>{0, 1}));
  // Places only: the first face walks out of its suppressed place and is picked again.
  const std::vector<std::size_t> places = MovingVisits(false);
  ASSERT_GE(places.size(), 3u) << ::testing::PrintToString(places);
  EXPECT_EQ(places[0], 0u);
  EXPECT_GE(std::count(places.begin(), places.end(), 0u), 2) << ::testing::PrintToString(places);
}

TEST(InhibitionOfReturn, SuppressionEndsAfterItsTime) {
  InhibitionOfReturn::Options options;
  options.fixation_time_s = 0.5;
  options.suppression_time_s = 1.2;
  InhibitionOfReturn ior(options);
  // Astronaut 0 .. 0.5 s (suppressed until 1.7 s), cat 0.5 .. 1.0 s (until 2.2 s), far face
  // 1.0 .. 1.5 s (until 2.7 s), nothing until 1.7 s, then the astronaut again.
  const std::vector<std::size_t> visits = Visits(ior, 2.0);
  EXPECT_EQ(visits, (std::vector<std::size_t>{1, 0, 2, 1}));
}

TEST(InhibitionOfReturn, AShortGlanceSuppressesNothing) {
  InhibitionOfReturn ior;  // 2 s to suppress
  const Vector3d astronaut = kTargets[1];
  for (int i = 0; i < 30; ++i) {  // 1 s on the astronaut
    EXPECT_EQ(ior.Select(i / 30.0, kTargets, kViewer, astronaut), std::optional<std::size_t>(1));
  }
  EXPECT_NEAR(ior.dwell_s(), 29 / 30.0, 1e-9);
  // A saccade elsewhere (no fixation) resets the dwell.
  ior.Select(1.0, kTargets, kViewer, std::nullopt);
  EXPECT_EQ(ior.dwell_s(), 0.0);
  EXPECT_TRUE(ior.suppressions().empty());
  EXPECT_FALSE(ior.IsSuppressed(astronaut, 1.0));
}

TEST(InhibitionOfReturn, SuppressesOnlyWithinTheRadius) {
  InhibitionOfReturn::Options options;
  options.fixation_time_s = 0.1;
  options.radius_m = 0.1;
  InhibitionOfReturn ior(options);
  const Vector3d p(2, 0, 1);
  ior.Select(0.0, {}, kViewer, p);
  ior.Select(0.2, {}, kViewer, p);
  ASSERT_EQ(ior.suppressions().size(), 1u);
  EXPECT_TRUE(ior.IsSuppressed(p + Vector3d(0, 0.09, 0), 0.3));
  EXPECT_FALSE(ior.IsSuppressed(p + Vector3d(0, 0.11, 0), 0.3));
  // A target 0.11 m away is still selectable; one 0.05 m away is not.
  const std::vector<Vector3d> near = {p + Vector3d(0, 0.05, 0), p + Vector3d(0, 0.11, 0)};
  EXPECT_EQ(ior.Select(0.3, near, kViewer, std::nullopt), std::optional<std::size_t>(1));
}

TEST(InhibitionOfReturn, NoCandidateSelectsNothing) {
  InhibitionOfReturn ior;
  EXPECT_EQ(ior.Select(0.0, {}, kViewer, std::nullopt), std::nullopt);
}

TEST(InhibitionOfReturn, BadOptionsSayWhatIsWrong) {
  InhibitionOfReturn::Options o;
  o.fixation_time_s = 0.0;
  try {
    InhibitionOfReturn ior(o);
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "InhibitionOfReturn::Options: fixation_time_s 0, expected (0, 1000000]");
  }
  std::string error;
  o = {};
  o.radius_m = -1;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_EQ(error, "InhibitionOfReturn::Options: radius_m -1, expected (0, 1000000]");
  o = {};
  o.suppression_time_s = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(o.IsValid(&error));
}

}  // namespace
}  // namespace saccade::vision
