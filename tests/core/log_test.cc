#include "saccade/core/log.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "saccade/core/error.h"

namespace saccade::log {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// Restores the level a test changed, so that the tests do not depend on their order.
class LogTest : public ::testing::Test {
 protected:
  void SetUp() override { saved_ = GetLevel(); }
  void TearDown() override { SetLevel(saved_); }
  Level saved_ = Level::kInfo;
};

TEST_F(LogTest, ParsesEveryLevelByTheNameItWrites) {
  for (Level level :
       {Level::kTrace, Level::kDebug, Level::kInfo, Level::kWarn, Level::kError, Level::kOff}) {
    EXPECT_EQ(ParseLevel(LevelName(level)), level) << LevelName(level);
  }
  EXPECT_EQ(ParseLevel("warning"), Level::kWarn);
}

TEST_F(LogTest, AnUnknownLevelNamesTheValueAndTheChoices) {
  try {
    ParseLevel("loud");
    FAIL() << "no exception";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("'loud'"));
    EXPECT_THAT(e.what(), HasSubstr("trace, debug, info, warn, error or off"));
  }
}

TEST_F(LogTest, WritesLinesAtOrAboveTheLevelToStderrWithTheLevelNamed) {
  SetLevel(Level::kWarn);
  ::testing::internal::CaptureStderr();
  Info("quiet {}", 1);
  Warn("servo {} overloaded", 3);
  Error("bus {}", "gone");
  const std::string out = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(out, Not(HasSubstr("quiet")));
  EXPECT_THAT(out, HasSubstr("[warning] servo 3 overloaded\n"));
  EXPECT_THAT(out, HasSubstr("[error] bus gone\n"));
}

TEST_F(LogTest, OffSilencesEvenErrors) {
  SetLevel(Level::kOff);
  EXPECT_FALSE(Enabled(Level::kError));
  ::testing::internal::CaptureStderr();
  Error("nobody hears this");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace saccade::log
