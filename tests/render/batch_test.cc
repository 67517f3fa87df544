// Renderer::RenderBatch (internal_batch.cc): N heads in one call equal N single renders of the
// same pinhole cameras, each head with its own joints and object placement; bad batches are
// refused naming what is wrong.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/render/renderer.h"
#include "saccade/scene/scene.h"

namespace saccade::render {
namespace {

using ::testing::HasSubstr;

// A batch tile and a single render draw the same triangles through the same projection. A tile
// far from the framebuffer's origin has window coordinates with less sub-pixel precision, so a
// few edge pixels may fall on the other side of an edge: measured 0.05 % of the pixels of a
// 1024 x 768 image off by more than 1 DN; allowed 0.1 %.
constexpr double kMaxDifferingShare = 1e-3;

RendererOptions PinholeOptions() {
  RendererOptions options;
  options.cameras = {"left", "right"};
  options.distortion = false;
  options.noise = false;
  options.motion_blur = false;
  return options;
}

scene::Scene LoadScene() {
  return scene::Scene::Load(SACCADE_SOURCE_DIR "/scenes/astronaut_and_cat.yaml");
}

TEST(RenderBatch, EachHeadEqualsASingleRenderOfItsState) {
  const scene::Scene scene = LoadScene();
  auto renderer = MakeRenderer(scene, PinholeOptions());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-0.2, 0.2);
  std::vector<BatchHead> heads(6);
  for (BatchHead& head : heads) {
    head.state = scene.InitialState();
    head.state.joints = head::JointState::Popeye(angle(rng), angle(rng), angle(rng), angle(rng));
  }
  const int w = scene.FindCamera("left")->model.intrinsics().width();
  const int h = scene.FindCamera("left")->model.intrinsics().height();
  const std::size_t image_bytes = static_cast<std::size_t>(w) * h * 3;
  std::vector<uint8_t> batch(heads.size() * 2 * image_bytes);
  renderer->RenderBatch(heads, batch.data(), batch.size());
  for (std::size_t i = 0; i < heads.size(); ++i) {
    const std::vector<Frame> frames = renderer->Render(heads[i].state, 0);
    for (int c = 0; c < 2; ++c) {
      const uint8_t* tile = batch.data() + (i * 2 + c) * image_bytes;
      std::size_t differing = 0;
      for (std::size_t k = 0; k < image_bytes; ++k) {
        differing += std::abs(int{tile[k]} - int{frames[c].color->data()[k]}) > 1;
      }
      EXPECT_LE(static_cast<double>(differing) / image_bytes, kMaxDifferingShare)
          << "head " << i << " camera " << c;
    }
  }
  // Each head its own state: the first two heads' left images differ.
  EXPECT_NE(0, std::memcmp(batch.data(), batch.data() + 2 * image_bytes, image_bytes));
}

TEST(RenderBatch, EachHeadEqualsItselfAloneToTheBitWhateverItsPlace) {
  // Every tile is drawn at the origin of its own layer, as a batch of one head is: the same
  // window coordinates, so the same pixels to the bit (the vector env equals single envs).
  const scene::Scene scene = LoadScene();
  auto renderer = MakeRenderer(scene, PinholeOptions());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(-0.2, 0.2);
  std::vector<BatchHead> heads(5);
  for (BatchHead& head : heads) {
    head.state = scene.InitialState();
    head.state.joints = head::JointState::Popeye(angle(rng), angle(rng), angle(rng), angle(rng));
  }
  const int w = scene.FindCamera("left")->model.intrinsics().width();
  const int h = scene.FindCamera("left")->model.intrinsics().height();
  const std::size_t pair_bytes = static_cast<std::size_t>(w) * h * 3 * 2;
  std::vector<uint8_t> batch(heads.size() * pair_bytes);
  renderer->RenderBatch(heads, batch.data(), batch.size());
  std::vector<uint8_t> alone(pair_bytes);
  for (std::size_t i = 0; i < heads.size(); ++i) {
    renderer->RenderBatch({heads[i]}, alone.data(), alone.size());
    std::size_t differing = 0;
    for (std::size_t k = 0; k < pair_bytes; ++k) {
      differing += batch[i * pair_bytes + k] != alone[k];
    }
    EXPECT_EQ(differing, 0u) << "head " << i;
  }
}

TEST(RenderBatch, HiddenAndMovedObjectsChangeOnlyTheirHead) {
  const scene::Scene scene = LoadScene();
  RendererOptions options = PinholeOptions();
  options.cameras = {"left"};
  auto renderer = MakeRenderer(scene, options);
  const std::size_t n = scene.objects().size();
  std::vector<BatchHead> heads(3);
  for (BatchHead& head : heads) head.state = scene.InitialState();
  heads[1].hidden.assign(n, true);
  heads[2].object_poses.resize(n);
  geometry::Pose moved = scene.ObjectPose(scene.objects()[0], heads[2].state);
  moved.translation().y() += 0.3;
  heads[2].object_poses[0] = moved;
  const auto& K = scene.FindCamera("left")->model.intrinsics();
  const std::size_t bytes = static_cast<std::size_t>(K.width()) * K.height() * 3;
  std::vector<uint8_t> out(3 * bytes);
  renderer->RenderBatch(heads, out.data(), out.size());
  EXPECT_NE(0, std::memcmp(out.data(), out.data() + bytes, bytes));
  EXPECT_NE(0, std::memcmp(out.data(), out.data() + 2 * bytes, bytes));
  // A second call with the first head alone draws it as before: no state leaks between heads.
  std::vector<uint8_t> again(bytes);
  renderer->RenderBatch({heads[0]}, again.data(), again.size());
  EXPECT_EQ(0, std::memcmp(out.data(), again.data(), bytes));
}

TEST(RenderBatch, TwoContextsGiveTheSameImagesToTheBitAsOne) {
  // Tall, narrow cameras (48 x 4096), 3 heads x 2 cameras: the second context's half (tiles 3
  // to 5) starts with the second head's right eye.
  std::string yaml = R"(
background: [0.62, 0.72, 0.82]
lights:
  - {type: ambient, intensity: 0.35}
  - {type: directional, direction: [0.4, -0.6, -1.0], intensity: 0.8}
ground: {size: 16, pattern: checker, cell: 0.5}
robot:
  head: )" SACCADE_SOURCE_DIR R"(/robots/popeye.yaml
  visible: false
  cameras:
    left: {calibration: {width: 48, height: 4096, fx: 600, fy: 600}}
    right: {calibration: {width: 48, height: 4096, fx: 600, fy: 600}}
objects:
  - {name: ball, kind: sphere, radius: 0.3, color: [0.8, 0.3, 0.2], pose: {position: [2, 0, 1.1]}}
  - {name: box, kind: box, size: 0.4, color: [0.2, 0.3, 0.9], pose: {position: [3, 0.1, 0.3]}}
)";
  const scene::Scene scene =
      scene::Scene::FromYamlString(yaml, "<tall cameras>", SACCADE_SOURCE_DIR);
  std::vector<BatchHead> heads(3);
  for (std::size_t i = 0; i < heads.size(); ++i) {
    heads[i].state = scene.InitialState();
    heads[i].state.joints =
        head::JointState::Popeye(0.01 * static_cast<double>(i), -0.1, 0.02, -0.02);
  }
  const std::size_t tile_bytes = 48 * 4096 * 3;
  std::vector<uint8_t> images[2], again[2];
  for (int contexts : {1, 2}) {
    RendererOptions options = PinholeOptions();
    options.batch_contexts = contexts;
    auto renderer = MakeRenderer(scene, options);
    images[contexts - 1].assign(heads.size() * 2 * tile_bytes, 0);
    renderer->RenderBatch(heads, images[contexts - 1].data(), images[contexts - 1].size());
    // A second, smaller batch on the same renderers (their framebuffers already larger).
    again[contexts - 1].assign(2 * tile_bytes, 0);
    renderer->RenderBatch({heads[2]}, again[contexts - 1].data(), again[contexts - 1].size());
  }
  EXPECT_TRUE(images[0] == images[1]);
  EXPECT_TRUE(again[0] == again[1]);
  // The third head alone is the third head of the batch.
  EXPECT_TRUE(std::equal(again[0].begin(), again[0].end(), images[0].begin() + 4 * tile_bytes));
  // Not blank: every tile shows the ball or the box against the sky and the ground.
  for (std::size_t tile = 0; tile < 6; ++tile) {
    const uint8_t* first = images[1].data() + tile * tile_bytes;
    const std::set<uint8_t> values(first, first + tile_bytes);
    EXPECT_GE(values.size(), 20u) << "tile " << tile;
  }
}

TEST(RenderBatch, RefusesBadBatchesNamingWhatIsWrong) {
  const scene::Scene scene = LoadScene();
  auto renderer = MakeRenderer(scene, PinholeOptions());
  std::vector<uint8_t> out(16);
  BatchHead head;
  head.state = scene.InitialState();
  try {
    renderer->RenderBatch({head}, out.data(), out.size());
    FAIL() << "a wrong output size was accepted";
  } catch (const InvalidArgument& error) {
    EXPECT_THAT(error.what(), HasSubstr("the output holds 16 bytes; expected 1 heads x 2 cameras"));
  }
  head.hidden = {true};
  try {
    renderer->RenderBatch({head}, out.data(), out.size());
    FAIL() << "a wrong hidden list was accepted";
  } catch (const InvalidArgument& error) {
    EXPECT_THAT(error.what(), HasSubstr("head 0: hidden has 1 entries; expected 0 or one per"));
  }
}

}  // namespace
}  // namespace saccade::render
