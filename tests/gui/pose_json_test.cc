// A pose has one JSON form everywhere (issue 46, item 3; docs/architecture.md): one pose,
// passed through every producer of poses in JSON (geometry/json.h's codec, the data set's
// frames.jsonl, the GUI's scene document and its state), gives the same text in each, and
// that text reads back to the same pose, bit for bit.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gui/internal_scene_document.h"
#include "saccade/core/error.h"
#include "saccade/geometry/image_camera.h"
#include "saccade/geometry/json.h"
#include "saccade/head/kinematics.h"
#include "saccade/render/dataset.h"
#include "saccade/scene/scene.h"
#include "saccade/server/gui_server.h"
#include "scene/scene_test_util.h"

namespace saccade {
namespace {

using nlohmann::json;
using scene::testing::TempDir;

// Poses with rotations and translations whose doubles need all 17 digits: a form that rounded
// them (a float, a fixed number of decimals) would not read back bit for bit.
const std::string kScene = R"(objects:
  - name: crate
    kind: box
    size: [0.2, 0.3, 0.4]
    pose:
      position: [1.1, -0.7, 0.3]
      rpy_deg: [12.3, -45.6, 78.9]
  - name: ball
    kind: sphere
    radius: 0.1
    motion:
      type: waypoints
      waypoints:
        - {time: 0, position: [1, 0.1, 1], rpy_deg: [0, 0, 10]}
        - {time: 2, position: [1.3, 1, 1], rpy_deg: [5, 0, 97]}
robot:
  head: )" + scene::testing::kPopeye +
                           R"(
  pose: {position: [0.3, 0.2, 1.1], rpy_deg: [0, 0, 21.7]}
cameras:
  - name: rig
    calibration: {width: 64, height: 48, fx: 50, fy: 51, cx: 32.3, cy: 23.9}
    pose:
      position: [0.1, -2.3, 1.7]
      rpy_deg: [-97.3, 1.1, 33.3]
)";

/// The text of geometry/json.h's form of X: what every producer must write.
std::string Form(const geometry::Pose& X) { return ToJson(X).dump(); }

/// Reads `j` back through the codec (geometry/json.h) and checks it is X to the bit.
void ExpectReadsBackExactly(const json& j, const geometry::Pose& X, const std::string& where) {
  // Through text, as a reader of the file or the message gets it.
  const geometry::Pose read = FromJson<geometry::Pose>(json::parse(j.dump()), where);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(read(r, c), X(r, c)) << where << " (" << r << ", " << c << ")";
    }
  }
}

/// One producer's pose `j` against X: the same text as the codec's, and X again when read.
void ExpectOneForm(const json& j, const geometry::Pose& X, const std::string& where) {
  EXPECT_EQ(j.dump(), Form(X)) << where;
  ExpectReadsBackExactly(j, X, where);
}

const scene::CameraSpec& Rig(const scene::Scene& scene) {
  const scene::CameraSpec* rig = scene.FindCamera("rig");
  if (rig == nullptr) throw Error("test: the scene has no camera 'rig'");
  return *rig;
}

class PoseJsonTest : public ::testing::Test {
 protected:
  PoseJsonTest() : scene_(scene::Scene::FromYamlString(kScene, "pose_json.yaml", dir_.path())) {}

  TempDir dir_;
  scene::Scene scene_;
};

TEST_F(PoseJsonTest, CodecWritesNestedRowsAndReadsBackBitForBit) {
  const geometry::Pose X = Rig(scene_).X_WC;
  const json j = ToJson(X);
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 4u);
  for (int r = 0; r < 4; ++r) {
    ASSERT_TRUE(j[r].is_array() && j[r].size() == 4u) << j.dump();
    for (int c = 0; c < 4; ++c) EXPECT_EQ(j[r][c].get<double>(), X(r, c)) << r << ", " << c;
  }
  EXPECT_EQ(j[3].dump(), "[0.0,0.0,0.0,1.0]");
  ExpectReadsBackExactly(j, X, "geometry/json.h");
}

TEST_F(PoseJsonTest, FramesJsonlWritesTheCodecsForm) {
  const scene::CameraSpec& rig = Rig(scene_);
  const geometry::Pose X_WC = rig.X_WC;
  const geometry::Pose X_WO = scene_.objects()[0].motion.PoseAt(0.0);
  const geometry::Pose X_CO = X_WC.inverse() * X_WO;

  auto image = std::make_shared<Image>(64, 48, PixelFormat::kRgb8);
  image->metadata().camera = "rig";
  geometry::SetCameraModel(image->metadata(),
                           std::make_shared<const geometry::CameraModel>(rig.model));
  geometry::SetCameraPose(image->metadata(), X_WC);
  render::Frame frame;
  frame.color = image;
  render::ObjectTruth truth;
  truth.id = scene_.objects()[0].id;
  truth.name = "crate";
  truth.X_WO = X_WO.matrix();
  truth.X_CO = X_CO.matrix();
  truth.pixels = 12;
  truth.x_min = truth.y_min = 1;
  truth.x_max = truth.y_max = 4;
  frame.objects.push_back(truth);

  render::TruthRequest request;
  request.boxes = true;
  const std::filesystem::path out = dir_.path() / "set";
  {
    render::DatasetWriter writer(scene_, {"rig"}, request, out, false, false);
    writer.Write(0, 0.0, scene_.InitialState(), {frame});
  }
  std::ifstream in(out / "frames.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(in, line)) << "frames.jsonl is empty";
  const json entry = json::parse(line).at("cameras").at("rig");
  ExpectOneForm(entry.at("X_WC"), X_WC, "frames.jsonl X_WC");
  ExpectOneForm(entry.at("objects").at(0).at("X_WO"), X_WO, "frames.jsonl X_WO");
  ExpectOneForm(entry.at("objects").at(0).at("X_CO"), X_CO, "frames.jsonl X_CO");
}

TEST_F(PoseJsonTest, SceneDocumentWritesTheCodecsForm) {
  server::GuiServer server(server::ServerOptions{});  // never started: it only holds documents
  const json doc = gui::internal::PublishScene(scene_, "pose_json", "gui", json::array(), server);
  bool rig_seen = false;
  for (const json& camera : doc.at("cameras")) {
    const scene::CameraSpec* spec = scene_.FindCamera(camera.at("name").get<std::string>());
    ASSERT_NE(spec, nullptr) << camera.dump();
    ExpectOneForm(camera.at("X_WC"), spec->X_WC, "scene document camera " + spec->name);
    rig_seen |= spec->name == "rig";
  }
  EXPECT_TRUE(rig_seen);
  ASSERT_EQ(doc.at("objects").size(), scene_.objects().size());
  for (std::size_t i = 0; i < scene_.objects().size(); ++i) {
    ExpectOneForm(doc.at("objects").at(i).at("X_WO"), scene_.objects()[i].motion.PoseAt(0.0),
                  "scene document object " + scene_.objects()[i].name);
  }
  const json& parts = doc.at("robot").at("parts");
  ASSERT_EQ(parts.size(), scene_.robot()->parts.size());
  ASSERT_FALSE(parts.empty());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    ExpectOneForm(parts.at(i).at("X_LinkPart"), scene_.robot()->parts[i].X_LinkPart,
                  "scene document robot part " + std::to_string(i));
  }
}

TEST_F(PoseJsonTest, StateWritesTheCodecsForm) {
  // The head's frames, each under its documented key: the root, the cameras, every link.
  const head::HeadModel& head = scene_.robot()->head;
  const head::JointState q = head::JointState::Popeye(0.1, -0.2, 0.03, -0.04);
  const head::HeadFrames fk =
      head::ForwardKinematics(*head.AppendixAHead(), head::PopeyeJoints::From(q));
  const json live = gui::internal::FramesJson(head, q);
  ASSERT_EQ(live.size(), 5u);
  ExpectOneForm(live.at("X_WB"), fk.X_WB, "state frames X_WB");
  ExpectOneForm(live.at("left"), fk.X_WCamLeft, "state frames left");
  ExpectOneForm(live.at("right"), fk.X_WCamRight, "state frames right");
  std::vector<geometry::Pose> X_WL;
  head.ForwardKinematics(q.values(), &X_WL);
  ASSERT_EQ(live.at("links").size(), X_WL.size());
  for (int l = 0; l < head.tree().num_links(); ++l) {
    ExpectOneForm(live.at("links").at(head.tree().link_name(l)), X_WL[l],
                  "state frames links " + head.tree().link_name(l));
  }

  const double t = 0.7;
  const json objects = gui::internal::MovingObjectsJson(scene_, t);
  ASSERT_EQ(objects.size(), 1u);  // the crate stands still
  EXPECT_EQ(objects.at(0).at("name"), "ball");
  ExpectOneForm(objects.at(0).at("X_WO"), scene_.objects()[1].motion.PoseAt(t),
                "state objects ball");
}

TEST(PoseJsonForm, TheOldFlatListIsRefusedNamingTheForm) {
  json flat = json::array();
  for (int i = 0; i < 16; ++i) flat.push_back(i % 5 == 0 ? 1.0 : 0.0);
  try {
    FromJson<geometry::Pose>(flat, "X_WC");
    FAIL() << "a flat list of 16 numbers was read as a pose";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("a 4x4 matrix, row by row"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("X_WC"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace saccade
