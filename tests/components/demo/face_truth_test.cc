// The demo's ground truth (components/demo/face_truth.h): which pictures of a scene hold a
// face, as the face detector finds it in their own textures.
#include "saccade/components/demo/face_truth.h"

#include <gtest/gtest.h>

#include <string>

#include "saccade/scene/scene.h"

namespace saccade::components::demo {
namespace {

const std::string kScene = std::string(SACCADE_SOURCE_DIR) + "/scenes/astronaut_and_cat.yaml";

TEST(FacePictures, OnlyTheAstronautHasAFaceTheCatIsADecoy) {
  const auto pictures = FindPictureFaces(scene::Scene::Load(kScene));
  ASSERT_EQ(pictures.size(), 2u);
  EXPECT_EQ(pictures[0].name, "astronaut");
  EXPECT_TRUE(pictures[0].has_face);
  EXPECT_EQ(pictures[1].name, "chelsea");
  EXPECT_FALSE(pictures[1].has_face);
  // A human face on a 0.8 m portrait, as the cascade boxes it.
  EXPECT_GT(pictures[0].width_m, 0.08);
  EXPECT_LT(pictures[0].width_m, 0.25);
}

}  // namespace
}  // namespace saccade::components::demo
