// The GUI protocol declared once (issue 46, gui/protocol.h): its checks refuse what breaks the
// table naming the message and the field, in the words of the page's (the shared cases of
// tests/gui/protocol_cases.json, which web/tests/protocol.test.mjs runs through protocol.js);
// every message the server writes conforms to it (the state in each of its forms, the scene
// document); the generated page names every message.
#include "saccade/gui/protocol.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "gui/internal_scene_document.h"
#include "gui/internal_state_message.h"
#include "saccade/scene/scene.h"
#include "saccade/server/gui_server.h"
#include "server/internal_server_core.h"

namespace saccade::gui {
namespace {

using nlohmann::json;
namespace protocol = gui::protocol;

const std::string kSource = SACCADE_SOURCE_DIR;

json ReadJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("test: cannot read " + path);
  return json::parse(in);
}

std::string Check(const json& c) {
  const std::string check = c.at("check");
  const json& message = c.at("message");
  if (check == "command") return protocol::CheckCommand(message);
  if (check == "server") return protocol::CheckServerMessage(message, c.value("command", ""));
  if (check == "frame") return protocol::CheckFrameHeader(message);
  if (check == "scene") return protocol::CheckSceneDocument(message);
  throw Error("test: unknown check " + check);
}

TEST(GuiProtocol, RefusesWhatBreaksTheTableNamingTheFieldInThePagesWords) {
  const json cases = ReadJson(kSource + "/tests/gui/protocol_cases.json");
  ASSERT_GT(cases.size(), 30u);
  int refused = 0;
  for (const json& c : cases) {
    EXPECT_EQ(Check(c), c.at("error").get<std::string>()) << c.dump();
    refused += !c.at("error").get<std::string>().empty();
  }
  EXPECT_GT(refused, 20);
}

TEST(GuiProtocol, DeclaresEveryMessageEachWay) {
  std::map<protocol::Channel, std::set<std::string>> types;
  for (const protocol::Message& m : protocol::Messages()) {
    EXPECT_TRUE(types[m.channel].insert(m.type).second) << "twice: " << m.type;
    EXPECT_EQ(m.body.kind, protocol::Kind::kObject) << m.type;
    EXPECT_FALSE(m.summary.empty()) << m.type;
  }
  EXPECT_EQ(types[protocol::Channel::kCommand],
            (std::set<std::string>{"joints", "fixate", "perception", "effects", "pause", "resume",
                                   "step", "record", "speed", "stop", "estop", "clear", "ping",
                                   "frame_window", "frame_ack"}));
  EXPECT_EQ(types[protocol::Channel::kText],
            (std::set<std::string>{"hello", "state", "map", "reply", "error", "event"}));
  EXPECT_EQ(types[protocol::Channel::kFrame], std::set<std::string>{"frame"});
  EXPECT_EQ(types[protocol::Channel::kDocument], std::set<std::string>{"scene"});
  // The server module answers flow control itself, within its own bound.
  const protocol::Message* window = protocol::Find(protocol::Channel::kCommand, "frame_window");
  ASSERT_NE(window, nullptr);
  EXPECT_TRUE(window->transport);
  EXPECT_EQ(window->body.fields.at(2).schema.max, server::internal_gui::kMaxFrameWindow);
}

class GuiProtocolMessages : public ::testing::Test {
 protected:
  GuiProtocolMessages() : scene_(scene::Scene::Load(kSource + "/scenes/portraits_moving.yaml")) {}

  scene::Scene scene_;
};

TEST_F(GuiProtocolMessages, TheStateConformsInEachOfItsForms) {
  ASSERT_TRUE(scene_.robot());
  // No head, no effects, no target: the nulls.
  internal::StateParts bare;
  bare.step = 0;
  bare.time = 0.05;
  json state = internal::StateJson(bare, scene_);
  EXPECT_EQ(protocol::CheckServerMessage(state), "") << state.dump();
  EXPECT_TRUE(state["joints"].is_null());
  EXPECT_FALSE(state["objects"].empty()) << "portraits_moving.yaml has moving objects";

  // Everything: the joints and frames, effects, a target with its errors, hw.head's status.
  internal::StateParts full = bare;
  full.step = 120;
  full.time = 4.8;
  full.paused = true;
  full.speed = 0.5;
  full.perception = true;
  full.effects = render::RendererOptions{};
  components::JointStateMessage joints;
  joints.positions = head::JointState::Popeye(0.1, -0.05, 0.03, -0.03);
  joints.targets = head::JointState::Popeye(0.2, -0.05, 0.03, -0.03);
  joints.arrived = false;
  full.joints = joints;
  full.head = &scene_.robot()->head;
  components::TargetMessage target;
  target.valid = true;
  target.target_id = 2;
  target.p_W = {1.5, 0.2, 1.1};
  full.target = target;
  full.step_ms = 38.0;
  full.steps_per_s = 9.5;
  full.realtime_factor = 0.38;
  full.frames_per_s = 9.5;
  full.head_status = {{"driver", "simulated"}, {"torque", true}};
  state = internal::StateJson(full, scene_);
  EXPECT_EQ(protocol::CheckServerMessage(state), "") << state.dump();
  EXPECT_FALSE(state["frames"].is_null());
  EXPECT_FALSE(state["fixation_error_deg"].is_null());

  // A field the code writes and the table does not declare is refused: the check is exact.
  state["stowaway"] = 1;
  EXPECT_EQ(protocol::CheckServerMessage(state),
            "state: unknown field 'stowaway' (expected step, time, paused, speed, perception, "
            "manual, effects, joints, frames, fixation_W, target, fixation_error_deg, objects, "
            "timing, head_status, recording)");
}

TEST_F(GuiProtocolMessages, TheSceneDocumentConforms) {
  server::GuiServer server(server::ServerOptions{});  // never started: it only holds documents
  const json commands = {{"effects", true}, {"perception", true}, {"estop", false}};
  const json doc = internal::PublishScene(scene_, "portraits_moving.yaml", "gui", commands, server);
  EXPECT_EQ(protocol::CheckSceneDocument(doc), "");
  EXPECT_FALSE(doc["models"].empty());
  // Without the commands it offers, the document breaks the table.
  json without = doc;
  without.erase("commands");
  EXPECT_EQ(protocol::CheckSceneDocument(without), "scene: missing field 'commands'");
}

TEST(GuiProtocol, ThePageNamesEveryMessageAndEveryField) {
  const std::string page = protocol::Markdown();
  for (const protocol::Message& m : protocol::Messages()) {
    const std::string title = m.channel == protocol::Channel::kDocument ? "/api/" + m.type : m.type;
    EXPECT_NE(page.find("`" + title + "`\n"), std::string::npos) << m.type;
    for (const protocol::Field& f : m.body.fields) {
      EXPECT_NE(page.find("`" + f.name + "`"), std::string::npos) << m.type << "." << f.name;
    }
  }
  // protocol.js holds the same table.
  const std::string js = protocol::JavaScript();
  EXPECT_NE(js.find("export const table = "), std::string::npos);
  EXPECT_NE(js.find("\"frame_window\""), std::string::npos);
}

// The map message: bounded, to the millimetre, conforming to the table however the map is.
TEST(GuiMapMessage, SendsEveryKthVoxelBeyondTheBoundToTheMillimetre) {
  components::MapMessage m;
  m.time = 2.5;
  m.frame_index = 62;
  m.resolution_m = 0.02;
  m.fused = 63;
  m.occupied_W = {{1.23456, -0.0004, 2.0}, {0.5, std::nan(""), 1.0}, {1.0, 1.0, 1.0}};
  m.inhibited = {{{1.0, 2.0, 0.5}, 0.15, 1.0}, {{0.0, 0.0, 0.0}, 0.1, 1.7}};
  json small = internal::MapJson(m);
  EXPECT_EQ(protocol::CheckServerMessage(small), "") << small.dump();
  EXPECT_EQ(small["total"], 3);
  EXPECT_EQ(small["points"], json({1.235, -0.0, 2.0, 1.0, 1.0, 1.0})) << "NaN point left out";
  EXPECT_EQ(small["inhibited"][1]["strength"], 1.0) << "clamped to the table's [0, 1]";
  EXPECT_EQ(small["resolution_m"], 0.02);

  // 120,001 voxels: every 3rd (ceil(120001 / 50000)), 40,001 points, the first and the last.
  m.occupied_W.clear();
  constexpr int kVoxels = 120001;
  for (int i = 0; i < kVoxels; ++i) m.occupied_W.emplace_back(0.001 * i, 0.0, 1.0);
  const json large = internal::MapJson(m);
  EXPECT_EQ(protocol::CheckServerMessage(large), "");
  EXPECT_EQ(large["total"], kVoxels);
  ASSERT_EQ(large["points"].size(), 3u * 40001);
  EXPECT_LE(large["points"].size() / 3, static_cast<std::size_t>(protocol::kMaxMapPoints));
  EXPECT_EQ(large["points"][3], 0.003);
  EXPECT_EQ(large["points"][3 * 40000], 120.0);
}

}  // namespace
}  // namespace saccade::gui
