// Inhibition of return in 3D: places decay as exp(-t / tau), are forgotten below forget_below,
// inhibit only within radius_m, and move with the object they are anchored to.
#include "saccade/mapping/inhibition_3d.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "saccade/core/error.h"

namespace saccade::mapping {
namespace {

using Eigen::Vector3d;

// Inhibition is exp() of doubles: equal to the closed form up to rounding.
constexpr double kExact = 1e-12;

Inhibition3d::Options Defaults() {
  Inhibition3d::Options options;
  options.time_constant_s = 2.0;
  options.radius_m = 0.2;
  options.forget_below = 0.05;
  return options;
}

TEST(Inhibition3d, VisitedPlaceIsInhibitedAndDecaysWithTheTimeConstant) {
  Inhibition3d ior(Defaults());
  const Vector3d p(2.0, 0.5, 1.2);
  ASSERT_TRUE(ior.Visit(p, 10.0));
  EXPECT_GT(ior.Inhibition(p, 10.0), 0.9);
  EXPECT_NEAR(ior.Inhibition(p, 10.0), 1.0, kExact);
  EXPECT_GT(ior.Inhibition(p, 10.1), 0.9);
  // One time constant later: exp(-1), at the centre and anywhere inside the ball.
  EXPECT_NEAR(ior.Inhibition(p, 12.0), std::exp(-1.0), kExact);
  EXPECT_NEAR(ior.Inhibition(p + Vector3d(0.0, 0.19, 0.0), 12.0), std::exp(-1.0), kExact);
  EXPECT_NEAR(ior.Inhibition(p, 13.0), std::exp(-1.5), kExact);
  // Before its visit the place does not exist yet.
  EXPECT_EQ(ior.Inhibition(p, 9.0), 0.0);
}

TEST(Inhibition3d, PlaceIsForgottenAfterTheForgetTime) {
  Inhibition3d ior(Defaults());
  const Vector3d p(1.0, -1.0, 0.8);
  ior.Visit(p, 0.0);
  const double forget_s = 2.0 * std::log(1.0 / 0.05);  // tau ln(1 / forget_below): 5.99 s
  EXPECT_NEAR(ior.forget_after_s(), forget_s, kExact);
  // Just before: still there, at about forget_below.
  EXPECT_NEAR(ior.Inhibition(p, forget_s - 1e-6), 0.05, 1e-6);
  EXPECT_GT(ior.Inhibition(p, forget_s - 1e-6), 0.0);
  // Just after: no inhibition, even before Forget prunes the list.
  EXPECT_EQ(ior.Inhibition(p, forget_s + 1e-6), 0.0);
  EXPECT_EQ(ior.places().size(), 1u);
  ior.Forget(forget_s - 1e-6);
  EXPECT_EQ(ior.places().size(), 1u);
  ior.Forget(forget_s + 1e-6);
  EXPECT_TRUE(ior.places().empty());
  EXPECT_EQ(ior.Inhibition(p, forget_s + 1e-6), 0.0);
}

TEST(Inhibition3d, VisitForgetsFadedPlaces) {
  Inhibition3d ior(Defaults());
  ior.Visit(Vector3d(0, 0, 1), 0.0);
  ior.Visit(Vector3d(1, 0, 1), 4.0);
  EXPECT_EQ(ior.places().size(), 2u);
  ior.Visit(Vector3d(2, 0, 1), 7.0);  // the first is 7 s old: forgotten after 5.99 s
  ASSERT_EQ(ior.places().size(), 2u);
  EXPECT_EQ(ior.places()[0].p_W, Vector3d(1, 0, 1));
  EXPECT_EQ(ior.places()[1].p_W, Vector3d(2, 0, 1));
}

TEST(Inhibition3d, PointsOutsideTheRadiusAreNotInhibited) {
  Inhibition3d ior(Defaults());
  const Vector3d p(0.0, 0.0, 1.0);
  ior.Visit(p, 0.0);
  EXPECT_NEAR(ior.Inhibition(p + Vector3d(0.0, 0.0, 0.199), 0.0), 1.0, kExact);
  EXPECT_EQ(ior.Inhibition(p + Vector3d(0.0, 0.0, 0.201), 0.0), 0.0);
  EXPECT_EQ(ior.Inhibition(p + Vector3d(0.15, 0.15, 0.0), 0.0), 0.0);  // 0.212 m away
  EXPECT_EQ(ior.Inhibition(Vector3d(5.0, 5.0, 5.0), 0.0), 0.0);
}

TEST(Inhibition3d, GaussianFalloffIsOneAtTheCentreAndZeroBeyondTheRadius) {
  Inhibition3d::Options options = Defaults();
  options.falloff = Inhibition3d::Falloff::kGaussian;
  Inhibition3d ior(options);
  const Vector3d p(0.0, 0.0, 1.0);
  ior.Visit(p, 0.0);
  EXPECT_NEAR(ior.Inhibition(p, 0.0), 1.0, kExact);
  // sigma = radius / 2 = 0.1 m: exp(-1/2) one sigma away, exp(-2) at the edge, 0 beyond.
  EXPECT_NEAR(ior.Inhibition(p + Vector3d(0.1, 0.0, 0.0), 0.0), std::exp(-0.5), kExact);
  EXPECT_NEAR(ior.Inhibition(p + Vector3d(0.0, 0.2, 0.0), 0.0), std::exp(-2.0), kExact);
  EXPECT_EQ(ior.Inhibition(p + Vector3d(0.0, 0.2001, 0.0), 0.0), 0.0);
  EXPECT_NEAR(ior.Inhibition(p + Vector3d(0.1, 0.0, 0.0), 2.0), std::exp(-0.5 - 1.0), kExact);
}

TEST(Inhibition3d, InhibitionIsTheLargestOverOverlappingPlaces) {
  Inhibition3d ior(Defaults());
  ior.Visit(Vector3d(0.0, 0.0, 1.0), 0.0);
  ior.Visit(Vector3d(0.3, 0.0, 1.0), 2.0);  // 0.3 m apart: two places, their balls overlap
  ASSERT_EQ(ior.places().size(), 2u);
  const Vector3d between(0.15, 0.0, 1.0);
  EXPECT_NEAR(ior.Inhibition(between, 2.0), 1.0, kExact);  // the newer one
  EXPECT_NEAR(ior.Inhibition(Vector3d(-0.1, 0.0, 1.0), 2.0), std::exp(-1.0), kExact);
}

TEST(Inhibition3d, RevisitWithinTheRadiusRenewsThePlace) {
  Inhibition3d ior(Defaults());
  ior.Visit(Vector3d(0.0, 0.0, 1.0), 0.0);
  ior.Visit(Vector3d(0.05, 0.0, 1.0), 3.0);  // dwelling on the same spot
  ASSERT_EQ(ior.places().size(), 1u);
  EXPECT_EQ(ior.places()[0].p_W, Vector3d(0.05, 0.0, 1.0));
  EXPECT_EQ(ior.places()[0].visit_time_s, 3.0);
  EXPECT_NEAR(ior.Inhibition(Vector3d(0.05, 0.0, 1.0), 3.0), 1.0, kExact);
}

TEST(Inhibition3d, AnchoredPlaceMovesWithItsObject) {
  Inhibition3d ior(Defaults());
  Eigen::Isometry3d X_WO = Eigen::Isometry3d::Identity();
  X_WO.translation() = Vector3d(2.0, 0.0, 1.0);
  const Vector3d p_W(2.0, 0.1, 1.2);  // a point on the object: (0, 0.1, 0.2) in its frame
  const Vector3d fixed_W(0.0, 0.0, 1.0);
  ASSERT_TRUE(ior.Visit(p_W, 0.0, /*object_id=*/7, X_WO));
  ASSERT_TRUE(ior.Visit(fixed_W, 0.0));
  ASSERT_EQ(ior.places().size(), 2u);
  EXPECT_TRUE((ior.places()[0].p_O - Vector3d(0.0, 0.1, 0.2)).norm() < kExact);

  // The object moves 1 m along y and turns 90 degrees about z.
  Eigen::Isometry3d X_WO2 = Eigen::Isometry3d::Identity();
  X_WO2.translate(Vector3d(2.0, 1.0, 1.0));
  X_WO2.rotate(Eigen::AngleAxisd(M_PI / 2, Vector3d::UnitZ()));
  ior.MoveObject(7, X_WO2);
  const Vector3d moved_W = X_WO2 * Vector3d(0.0, 0.1, 0.2);  // (1.9, 1.0, 1.2)
  EXPECT_TRUE((ior.places()[0].p_W - moved_W).norm() < kExact);
  EXPECT_TRUE((moved_W - Vector3d(1.9, 1.0, 1.2)).norm() < kExact);
  EXPECT_NEAR(ior.Inhibition(moved_W, 1.0), std::exp(-0.5), kExact);
  EXPECT_EQ(ior.Inhibition(p_W, 1.0), 0.0);  // its old place is free
  // Another object moving, or this one again, leaves the world-fixed place where it was.
  ior.MoveObject(8, X_WO);
  EXPECT_EQ(ior.places()[1].p_W, fixed_W);
  EXPECT_NEAR(ior.Inhibition(fixed_W, 1.0), std::exp(-0.5), kExact);
  // A visit on the object near the place renews it rather than adding one.
  ASSERT_TRUE(ior.Visit(moved_W + Vector3d(0.0, 0.05, 0.0), 1.0, 7, X_WO2));
  EXPECT_EQ(ior.places().size(), 2u);
}

TEST(Inhibition3d, TimeGoingBackIsANewRun) {
  Inhibition3d ior(Defaults());
  ior.Visit(Vector3d(0, 0, 1), 5.0);
  ior.Visit(Vector3d(1, 0, 1), 6.0);
  EXPECT_EQ(ior.places().size(), 2u);
  // Inhibition does not change anything: it ignores places not yet visited at its time.
  EXPECT_EQ(ior.Inhibition(Vector3d(1, 0, 1), 5.5), 0.0);
  EXPECT_EQ(ior.places().size(), 2u);
  // A visit at an earlier time (the simulation restarted) clears the places first.
  ior.Visit(Vector3d(2, 0, 1), 0.5);
  ASSERT_EQ(ior.places().size(), 1u);
  EXPECT_EQ(ior.places()[0].p_W, Vector3d(2, 0, 1));
  EXPECT_EQ(ior.Inhibition(Vector3d(0, 0, 1), 5.0), 0.0);
  // So does Forget.
  ior.Forget(0.1);
  EXPECT_TRUE(ior.places().empty());
  // Reset forgets everything and the latest time.
  ior.Visit(Vector3d(3, 0, 1), 9.0);
  ior.Reset();
  EXPECT_TRUE(ior.places().empty());
  EXPECT_EQ(ior.Inhibition(Vector3d(3, 0, 1), 9.0), 0.0);
}

TEST(Inhibition3d, NonFiniteInputsAreIgnored) {
  Inhibition3d ior(Defaults());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(ior.Visit(Vector3d(nan, 0, 1), 0.0));
  EXPECT_FALSE(ior.Visit(Vector3d(0, 0, 1), std::numeric_limits<double>::infinity()));
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = nan;
  EXPECT_FALSE(ior.Visit(Vector3d(0, 0, 1), 0.0, 1, bad));
  EXPECT_TRUE(ior.places().empty());
  ASSERT_TRUE(ior.Visit(Vector3d(0, 0, 1), 0.0, 1, Eigen::Isometry3d::Identity()));
  ior.MoveObject(1, bad);
  EXPECT_EQ(ior.places()[0].p_W, Vector3d(0, 0, 1));
  EXPECT_EQ(ior.Inhibition(Vector3d(0, 0, 1), nan), 0.0);
}

// The message of the constructor's InvalidArgument, or "" when it does not throw.
std::string Refusal(const Inhibition3d::Options& options) {
  try {
    Inhibition3d ior(options);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(Inhibition3d, InvalidOptionsThrowNamingTheKey) {
  EXPECT_EQ(Refusal(Inhibition3d::Options()), "");
  for (double tau : {-1.0, 0.0, std::numeric_limits<double>::quiet_NaN()}) {
    Inhibition3d::Options options;
    options.time_constant_s = tau;
    const std::string message = Refusal(options);
    EXPECT_NE(message.find("time_constant_s"), std::string::npos) << message;
    EXPECT_NE(message.find("expected (0, "), std::string::npos) << message;
  }
  Inhibition3d::Options options;
  options.radius_m = 0.0;
  EXPECT_NE(Refusal(options).find("radius_m 0, expected (0, "), std::string::npos)
      << Refusal(options);
  for (double below : {0.0, 1.0, -0.5, 2.0}) {
    options = Inhibition3d::Options();
    options.forget_below = below;
    const std::string message = Refusal(options);
    EXPECT_NE(message.find("forget_below"), std::string::npos) << message;
    EXPECT_NE(message.find("expected (0, 1)"), std::string::npos) << message;
  }
  options = Inhibition3d::Options();
  options.falloff = static_cast<Inhibition3d::Falloff>(9);
  EXPECT_NE(Refusal(options).find("falloff 9"), std::string::npos) << Refusal(options);
  std::string error;
  options = Inhibition3d::Options();
  options.time_constant_s = -1.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("time_constant_s"), std::string::npos) << error;
  EXPECT_FALSE(options.IsValid(nullptr));
}

}  // namespace
}  // namespace saccade::mapping
