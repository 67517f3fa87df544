// The temporaries of atomic writes (issue 46, item 9): their name, and the removal of those a
// killed run left, which touches no other file.

#include "saccade/core/temporary_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "saccade/core/error.h"
#include "saccade/core/image.h"
#include "saccade/core/image_io.h"

namespace saccade {
namespace {

namespace fs = std::filesystem;

class TemporaryFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("saccade_temporary_file_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void Touch(const std::string& name) const { std::ofstream(dir_ / name) << "x"; }
  std::set<std::string> Names() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) {
      names.insert(entry.path().filename().string());
    }
    return names;
  }
  fs::path dir_;
};

TEST(TemporaryFileNameTest, NamesAreHiddenBesideThePathWithPidAndCounter) {
  const fs::path temporary = TemporaryPathFor("out/left/000007.png", 3);
  EXPECT_EQ(temporary.parent_path(), fs::path("out/left"));
  EXPECT_EQ(temporary.filename().string(), ".000007.png.tmp" + std::to_string(::getpid()) + "_3");
  EXPECT_TRUE(IsTemporaryFileName(temporary.filename().string()));
}

TEST(TemporaryFileNameTest, OnlyTheWritersOwnPatternMatches) {
  for (const char* name :
       {".000000.png.tmp123_0", ".left.yaml.tmp99999_41", ".a.tmp1_2", ".x.tmp.tmp7_8"}) {
    EXPECT_TRUE(IsTemporaryFileName(name)) << name;
  }
  for (const char* name :
       {"000000.png", "000000.png.tmp123_0", ".000000.png", ".000000.png.tmp", ".000000.png.tmp_1",
        ".000000.png.tmp12_", ".000000.png.tmp12", ".000000.png.tmpabc_1", ".000000.png.tmp1_2x",
        ".tmp1_2", ".notes.txt", ".000000.png.tmp1_2.png", "", "."}) {
    EXPECT_FALSE(IsTemporaryFileName(name)) << name;
  }
}

TEST_F(TemporaryFileTest, StaleTemporariesAreRemovedAndNothingElse) {
  for (const char* name :
       {".000000.png.tmp4194305_0", ".000001.png.tmp4194305_17", ".left.yaml.tmp99_3", "000000.png",
        "notes.txt", ".hidden", "000000.png.tmp4194305_0", ".000000.png.tmpX_0"}) {
    Touch(name);
  }
  fs::create_directories(dir_ / ".depth.tmp5_5");  // a folder of that name is not ours
  const std::string own = ".000002.png.tmp" + std::to_string(::getpid()) + "_0";
  Touch(own);  // a write of this process, in progress
  EXPECT_EQ(RemoveStaleTemporaries(dir_), 3);
  EXPECT_EQ(Names(),
            (std::set<std::string>{"000000.png", "notes.txt", ".hidden", "000000.png.tmp4194305_0",
                                   ".000000.png.tmpX_0", ".depth.tmp5_5", own}));
  EXPECT_EQ(RemoveStaleTemporaries(dir_), 0);
  EXPECT_EQ(RemoveStaleTemporaries(dir_ / "missing"), 0);
}

TEST_F(TemporaryFileTest, WritePngLeavesNoTemporaryBehind) {
  Image image(4, 3, PixelFormat::kRgb8);
  WritePng(image.view(), dir_ / "000000.png");
  EXPECT_EQ(Names(), (std::set<std::string>{"000000.png"}));
}

}  // namespace
}  // namespace saccade
