// The fuzzer's seed corpus (fuzz/corpus/scene) stays what its names say: valid_* files load,
// invalid_* files are rejected with a FileError naming the file. Paths resolve against
// scenes/, as in fuzz/scene_fuzzer.cc.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "saccade/core/error.h"
#include "saccade/scene/scene.h"
#include "scene/scene_test_util.h"

namespace saccade::scene {
namespace {

TEST(FuzzCorpus, ValidSeedsLoadAndInvalidSeedsAreRejected) {
  const std::filesystem::path corpus = testing::kSourceDir + "/fuzz/corpus/scene";
  const std::filesystem::path base_dir = testing::kSourceDir + "/scenes";
  int valid = 0, invalid = 0;
  for (const auto& entry : std::filesystem::directory_iterator(corpus)) {
    const std::string name = entry.path().filename().string();
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (name.rfind("valid_", 0) == 0) {
      EXPECT_NO_THROW(Scene::FromYamlString(text, name, base_dir)) << name;
      ++valid;
    } else if (name.rfind("invalid_", 0) == 0) {
      try {
        Scene::FromYamlString(text, name, base_dir);
        ADD_FAILURE() << name << " loaded";
      } catch (const FileError& error) {
        EXPECT_EQ(error.file(), name) << error.what();
        EXPECT_GT(error.line(), 0) << error.what();
      }
      ++invalid;
    } else {
      ADD_FAILURE() << "seed " << name << " is neither valid_* nor invalid_*";
    }
  }
  EXPECT_GE(valid, 3);
  EXPECT_GE(invalid, 3);
}

}  // namespace
}  // namespace saccade::scene
