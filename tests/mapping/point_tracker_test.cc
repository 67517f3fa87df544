// PointTracker: points found anew each frame keep their ids while they move within the gate,
// and inhibition of return anchored to a track follows the object.
#include "saccade/mapping/point_tracker.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <string>

#include "saccade/core/error.h"
#include "saccade/mapping/inhibition_3d.h"

namespace saccade::mapping {
namespace {

using Eigen::Vector3d;

TEST(PointTracker, TwoCrossingPointsKeepTheirIdsStepByStep) {
  PointTracker tracker;  // gate 0.25 m
  // Two faces 1 m apart walk towards each other 5 cm a step and pass 10 cm apart (in y).
  const Vector3d a0(2.0, -0.5, 1.5), b0(2.0, 0.5, 1.6);
  std::vector<int> first;
  for (int k = 0; k <= 20; ++k) {
    const Vector3d a = a0 + Vector3d(0, 0.05 * k, 0), b = b0 - Vector3d(0, 0.05 * k, 0);
    // Given in either order: the ids follow the points, not the order.
    const bool swap = k % 2 == 1;
    const std::vector<int> ids =
        tracker.Update(swap ? std::vector{b, a} : std::vector{a, b}, 0.2 * k);
    const int id_a = swap ? ids[1] : ids[0], id_b = swap ? ids[0] : ids[1];
    if (k == 0) {
      first = {id_a, id_b};
      EXPECT_NE(id_a, id_b);
    }
    ASSERT_EQ(id_a, first[0]) << "step " << k;
    ASSERT_EQ(id_b, first[1]) << "step " << k;
  }
  EXPECT_EQ(tracker.tracks().size(), 2u);
}

TEST(PointTracker, AJumpBeyondTheGateOrAnAbsenceBeyondLostAfterStartsANewTrack) {
  PointTracker::Options options;
  options.gate_m = 0.2;
  options.lost_after_s = 1.0;
  PointTracker tracker(options);
  const int id = tracker.Update({Vector3d(1, 0, 1)}, 0.0)[0];
  EXPECT_EQ(tracker.Update({Vector3d(1.19, 0, 1)}, 0.1)[0], id);  // within the gate
  const int jumped = tracker.Update({Vector3d(1.6, 0, 1)}, 0.2)[0];
  EXPECT_NE(jumped, id);
  // Unseen for 1 s exactly: kept; for more: dropped, and the same place is a new track.
  EXPECT_EQ(tracker.Update({Vector3d(1.6, 0, 1)}, 1.2)[0], jumped);
  const int again = tracker.Update({Vector3d(1.6, 0, 1)}, 2.3)[0];
  EXPECT_NE(again, jumped);
  EXPECT_NE(again, id);
  // Time going back is a new run: every track dropped.
  const int reset = tracker.Update({Vector3d(1.6, 0, 1)}, 0.0)[0];
  EXPECT_NE(reset, again);
  EXPECT_EQ(tracker.tracks().size(), 1u);
}

TEST(PointTracker, SeenNearFindsOnlyTracksOfTheLatestUpdate) {
  PointTracker tracker;
  tracker.Update({Vector3d(1, 0, 1), Vector3d(3, 0, 1)}, 0.0);
  ASSERT_TRUE(tracker.SeenNear(Vector3d(1.1, 0, 1), 0.3).has_value());
  EXPECT_FALSE(tracker.SeenNear(Vector3d(2, 0, 1), 0.3).has_value());
  tracker.Update({Vector3d(3, 0, 1)}, 0.1);  // the first is not seen this time
  EXPECT_FALSE(tracker.SeenNear(Vector3d(1.1, 0, 1), 0.3).has_value());
  const auto far = tracker.SeenNear(Vector3d(2.9, 0, 1), 0.3);
  ASSERT_TRUE(far.has_value());
  EXPECT_EQ(far->p_W, Vector3d(3, 0, 1));
}

TEST(PointTracker, NonFinitePointsOrTimesTouchNoTrackAndBadOptionsAreRefused) {
  PointTracker tracker;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<int> ids = tracker.Update({Vector3d(nan, 0, 0), Vector3d(1, 0, 0)}, 0.0);
  EXPECT_EQ(ids[0], -1);
  EXPECT_GE(ids[1], 0);
  EXPECT_EQ(tracker.Update({Vector3d(1, 0, 0)}, nan), std::vector<int>{-1});
  EXPECT_EQ(tracker.tracks().size(), 1u);
  PointTracker::Options bad;
  bad.gate_m = 0.0;
  try {
    PointTracker refused(bad);
    FAIL() << "a gate of 0 was taken";
  } catch (const InvalidArgument& error) {
    EXPECT_NE(std::string(error.what()).find("gate_m"), std::string::npos) << error.what();
  }
}

// The use it is made for: a face fixated at t = 0 walks 1.2 m in 3 s; the place inhibition of
// return holds moves with it (anchored to its track), so it stays inhibited where it went and
// where it was is free, while a world-anchored place stays behind.
TEST(PointTracker, InhibitionAnchoredToATrackFollowsTheMovingFace) {
  Inhibition3d::Options options;
  options.time_constant_s = 10.0;
  options.radius_m = 0.3;
  Inhibition3d anchored(options), world(options);
  PointTracker tracker;
  const Vector3d start(2.0, -0.6, 1.5);
  tracker.Update({start}, 0.0);
  const auto track = tracker.SeenNear(start, options.radius_m);
  ASSERT_TRUE(track.has_value());
  const Eigen::Isometry3d X_WO(Eigen::Translation3d(track->p_W));
  ASSERT_TRUE(anchored.Visit(start, 0.0, track->id, X_WO));
  ASSERT_TRUE(world.Visit(start, 0.0));
  Vector3d face = start;
  for (int k = 1; k <= 30; ++k) {
    face = start + Vector3d(0, 0.04 * k, 0);  // 0.4 m/s, seen at 10 Hz
    const std::vector<int> ids = tracker.Update({face}, 0.1 * k);
    ASSERT_EQ(ids[0], track->id) << "step " << k;
    anchored.MoveObject(ids[0], Eigen::Isometry3d(Eigen::Translation3d(face)));
  }
  const double decay = std::exp(-3.0 / 10.0);
  EXPECT_NEAR(anchored.Inhibition(face, 3.0), decay, 1e-12);
  EXPECT_EQ(anchored.Inhibition(start, 3.0), 0.0);
  EXPECT_EQ(world.Inhibition(face, 3.0), 0.0);
  EXPECT_NEAR(world.Inhibition(start, 3.0), decay, 1e-12);
}

}  // namespace
}  // namespace saccade::mapping
