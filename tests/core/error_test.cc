#include "saccade/core/error.h"

#include <gtest/gtest.h>

namespace saccade {
namespace {

TEST(FileError, MessageNamesFileLineAndKey) {
  const FileError error("robots/x.yaml", 14, "joints[2].limits", "expected 2 numbers, got 3");
  EXPECT_STREQ(error.what(), "robots/x.yaml:14: joints[2].limits: expected 2 numbers, got 3");
  EXPECT_EQ(error.line(), 14);
  EXPECT_EQ(error.key(), "joints[2].limits");
}

TEST(FileError, WholeFileErrorsOmitLineAndKey) {
  const FileError error("missing.yaml", 0, "", "cannot open: No such file or directory");
  EXPECT_STREQ(error.what(), "missing.yaml: cannot open: No such file or directory");
}

TEST(Assert, AbortsWithMessageOnBrokenInvariant) {
  EXPECT_DEATH(SACCADE_ASSERT(1 + 1 == 3, "arithmetic"), "internal error.*arithmetic");
}

}  // namespace
}  // namespace saccade
