// `saccade gui` as a script would use it (docs/gui-protocol.md): the real program on a real
// scene, over HTTP and WebSocket (Boost.Beast's client). The server-side checks of the
// commands that move the head: joint limits, reachability, malformed values; the scene
// document and meshes; pause, step, effects; camera frames. Every message the program sends
// is checked against the protocol's table (gui/protocol.h). The browser tests
// (web/tests/gui.test.mjs) drive the page itself.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "e2e/run_saccade.h"
#include "saccade/geometry/json.h"
#include "saccade/gui/protocol.h"

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using nlohmann::json;
using ::testing::HasSubstr;
using tcp = asio::ip::tcp;

const std::string kSource = SACCADE_SOURCE_DIR;
const std::string kScene = kSource + "/scenes/astronaut_and_cat.yaml";

// `saccade ARGS` (gui ..., demo --gui ...) in the background; the constructor waits for its
// address.
class GuiProcess {
 public:
  explicit GuiProcess(std::vector<std::string> args)
      : process_([&] {
          args.insert(args.begin(), SACCADE_BINARY);
          return args;
        }()) {
    // The scene loads and the renderer starts first: up to a minute on a busy machine.
    while (const std::optional<std::string> line = process_.ReadLine()) {
      output_ += *line;
      const auto at = line->find("http://127.0.0.1:");
      if (line->rfind("gui: serving", 0) == 0 && at != std::string::npos) {
        port_ = std::stoi(line->substr(at + std::strlen("http://127.0.0.1:")));
        // The access token in the printed address (a random one per run unless --no-token).
        const auto token = line->find("?token=", at);
        if (token != std::string::npos) {
          const auto begin = token + std::strlen("?token=");
          token_ = line->substr(begin, line->find_first_of(" \t", begin) - begin);
        }
        break;
      }
    }
  }
  // SIGTERM, then what it printed until it exited, and its exit status.
  int Stop() { return process_.Stop(&output_); }
  int port() const { return port_; }
  const std::string& token() const { return token_; }
  // `target` with the access token, as the page sends it.
  std::string WithToken(const std::string& target) const {
    if (token_.empty()) return target;
    return target + (target.find('?') == std::string::npos ? "?" : "&") + "token=" + token_;
  }
  const std::string& output() const { return output_; }
  // Reads its output until a line holding `text` (false when it ended or `timeout` passed).
  bool ReadUntil(const std::string& text, std::chrono::milliseconds timeout) {
    return process_.ReadUntil(text, &output_, timeout);
  }

 private:
  saccade::e2e::BackgroundProcess process_;
  int port_ = -1;
  std::string token_;
  std::string output_;
};

// GET `target` as it is, naming `host` in the Host header.
http::response<http::string_body> GetRaw(int port, const std::string& target,
                                         const std::string& host = "127.0.0.1") {
  asio::io_context io;
  tcp::socket socket(io);
  socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<uint16_t>(port)));
  http::request<http::string_body> request(http::verb::get, target, 11);
  request.set(http::field::host, host);
  http::write(socket, request);
  beast::flat_buffer buffer;
  http::response<http::string_body> response;
  http::read(socket, buffer, response);
  return response;
}

// GET `target` with the process's token, as the page asks.
http::response<http::string_body> Get(const GuiProcess& gui, const std::string& target,
                                      const std::string& host = "127.0.0.1") {
  return GetRaw(gui.port(), gui.WithToken(target), host);
}

// A WebSocket client that reads until a message it wants arrives. Every message it reads must
// conform to the protocol's table: a text message (a reply to the command of its id), a frame's
// header.
class Client {
 public:
  // Connects with the process's token, as the page does.
  explicit Client(const GuiProcess& gui) : ws_(io_) {
    tcp::socket& socket = ws_.next_layer();
    socket.connect(
        tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<uint16_t>(gui.port())));
    ws_.handshake("127.0.0.1", gui.WithToken("/ws"));
  }
  // The next text message satisfying `want` (binary frames go to frames_), within 120 s.
  json WaitFor(const std::function<bool(const json&)>& want) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    while (std::chrono::steady_clock::now() < deadline) {
      beast::flat_buffer buffer;
      ws_.read(buffer);
      const std::string data = beast::buffers_to_string(buffer.data());
      if (!ws_.got_text()) {
        uint32_t n = 0;
        std::memcpy(&n, data.data(), std::min<std::size_t>(4, data.size()));
        EXPECT_EQ(saccade::gui::protocol::CheckFrameHeader(json::parse(data.substr(4, n))), "");
        binary_.push_back(data);
        continue;
      }
      json message = json::parse(data);
      const auto sent = commands_.find(
          message.value("id", json()).is_number_integer() ? message["id"].get<int64_t>() : -1);
      EXPECT_EQ(saccade::gui::protocol::CheckServerMessage(
                    message, sent == commands_.end() ? "" : sent->second),
                "")
          << data;
      if (want(message)) return message;
    }
    ADD_FAILURE() << "no such message within 120 s";
    return json();
  }
  json Command(json command) {
    command["id"] = ++id_;
    commands_[id_] = command.value("type", "");
    ws_.text(true);
    ws_.write(asio::buffer(command.dump()));
    const int64_t id = id_;
    return WaitFor([id](const json& m) {
      return (m["type"] == "reply" || m["type"] == "error") && m.contains("id") && m["id"] == id;
    });
  }
  json State(const std::function<bool(const json&)>& want = [](const json&) { return true; }) {
    return WaitFor([&](const json& m) { return m["type"] == "state" && want(m); });
  }
  const std::vector<std::string>& binary() const { return binary_; }

 private:
  asio::io_context io_;
  websocket::stream<tcp::socket> ws_;
  int64_t id_ = 0;
  std::map<int64_t, std::string> commands_;  // the type of each command sent, by id
  std::vector<std::string> binary_;
};

// A pose of the protocol, read through its one form (geometry/json.h: 4x4, row by row); throws
// naming the form when it is anything else.
Eigen::Matrix4d Matrix(const json& m) {
  return saccade::FromJson<saccade::geometry::Pose>(m, "pose").matrix();
}

// Angle (deg) between a camera's optical axis (state.frames[camera]) and the way to p_W.
double AxisErrorDeg(const json& state, const std::string& camera, const Eigen::Vector3d& p_W) {
  const Eigen::Matrix4d X = Matrix(state["frames"][camera]);
  const Eigen::Vector3d axis = X.block<3, 1>(0, 2);
  const Eigen::Vector3d to = (p_W - X.block<3, 1>(0, 3)).normalized();
  return std::acos(std::clamp(axis.dot(to), -1.0, 1.0)) * 180.0 / M_PI;
}

class GuiCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    gui_ = new GuiProcess({"gui", "--scene", kScene, "--port", "0", "--paused"});
  }
  static void TearDownTestSuite() {
    delete gui_;
    gui_ = nullptr;
  }
  static GuiProcess* gui_;
};
GuiProcess* GuiCliTest::gui_ = nullptr;

TEST_F(GuiCliTest, ServesTheSceneAndItsMeshesAsTheRendererLoadedThem) {
  ASSERT_GT(gui_->port(), 0) << gui_->output();
  const auto scene_response = Get(*gui_, "/api/scene");
  ASSERT_EQ(scene_response.result_int(), 200);
  const json scene = json::parse(scene_response.body());
  EXPECT_EQ(saccade::gui::protocol::CheckSceneDocument(scene), "");
  EXPECT_EQ(scene["protocol"], "saccade-gui");
  EXPECT_EQ(scene["version"], 2);
  EXPECT_EQ(scene["mode"], "gui");
  std::vector<std::string> names;
  for (const json& o : scene["objects"]) names.push_back(o["name"]);
  EXPECT_THAT(names, ::testing::Contains("chelsea"));
  ASSERT_EQ(scene["head"]["joints"].size(), 4u);
  EXPECT_EQ(scene["head"]["joints"][0]["name"], "pan");
  ASSERT_FALSE(scene["robot"].is_null());
  EXPECT_FALSE(scene["robot"]["parts"].empty());
  // Every model's binary has exactly the bytes its mesh list announces.
  for (const json& model : scene["models"]) {
    std::size_t expected = 0;
    for (const json& mesh : model["meshes"]) {
      const std::size_t v = mesh["vertices"], i = mesh["indices"];
      expected += v * 6 * 4 + (mesh["uvs"].get<bool>() ? v * 2 * 4 : 0) + i * 4;
    }
    const auto bin = Get(*gui_, model["url"].get<std::string>());
    EXPECT_EQ(bin.result_int(), 200) << model["url"];
    EXPECT_EQ(bin.body().size(), expected) << model["url"];
    for (const json& material : model["materials"]) {
      if (material["texture"].is_null()) continue;
      const auto png = Get(*gui_, material["texture"].get<std::string>());
      ASSERT_EQ(png.result_int(), 200);
      EXPECT_EQ(png.body().substr(1, 3), "PNG");
    }
  }
  // The page and three.js come from the repository, not the internet.
  const auto page = Get(*gui_, "/");
  EXPECT_EQ(page.result_int(), 200);
  EXPECT_THAT(page.body(), HasSubstr("/vendor/three/"));
  EXPECT_EQ(Get(*gui_, "/vendor/three/build/three.module.js").result_int(), 200);
}

TEST_F(GuiCliTest, RejectsJointsOutsideTheLimitsAndMovesNothing) {
  ASSERT_GT(gui_->port(), 0) << gui_->output();
  Client client(*gui_);
  const json hello = client.WaitFor([](const json& m) { return m["type"] == "hello"; });
  EXPECT_EQ(hello["protocol"], "saccade-gui");
  const json scene = json::parse(Get(*gui_, "/api/scene").body());
  const double pan_max = scene["head"]["joints"][0]["max"];
  const json before = client.State();
  EXPECT_TRUE(before["paused"].get<bool>());

  json error = client.Command({{"type", "joints"}, {"positions", {{"pan", pan_max + 0.1}}}});
  EXPECT_EQ(error["type"], "error");
  EXPECT_THAT(error["error"].get<std::string>(), HasSubstr("pan"));
  EXPECT_THAT(error["error"].get<std::string>(), HasSubstr("outside its limits"));
  error = client.Command({{"type", "joints"}, {"positions", {{"pan", "left"}}}});
  EXPECT_EQ(error["error"], "joints: field 'positions.pan' must be a number, got string");
  error = client.Command({{"type", "joints"}, {"positions", {{"neck", 0.1}}}});
  EXPECT_EQ(error["error"],
            "joints: the head has no joint 'neck'; its joints are: pan, tilt, left, right");
  error = client.Command({{"type", "step"}, {"count", 5000}});
  EXPECT_EQ(error["error"], "step: field 'count' must be in [1, 1000], got 5000");
  error = client.Command({{"type", "fixate"}, {"p_W", {1.0, 0.0}}});
  EXPECT_EQ(error["error"], "fixate: field 'p_W' must have 3 items, got 2");
  error = client.Command({{"type", "fly"}});
  EXPECT_THAT(error["error"].get<std::string>(), HasSubstr("unknown command type 'fly'"));
  error = client.Command({{"type", "speed"}, {"factor", 100}});
  EXPECT_EQ(error["error"], "speed: field 'factor' must be in [0.05, 10], got 100");
  error = client.Command({{"type", "estop"}});
  EXPECT_THAT(error["error"].get<std::string>(), HasSubstr("only a hardware head"));
  // Behind the head: no fixation, with the reason.
  error = client.Command({{"type", "fixate"}, {"p_W", {-3.0, 0.0, 1.2}}});
  EXPECT_EQ(error["type"], "error");
  EXPECT_THAT(error["error"].get<std::string>(), HasSubstr("cannot be fixated"));

  // One step later the targets are where they were.
  EXPECT_EQ(client.Command({{"type", "step"}})["type"], "reply");
  const int64_t step = before["step"];
  const json after = client.State([&](const json& s) { return s["step"] > step; });
  EXPECT_EQ(after["joints"]["targets"], before["joints"]["targets"]);
}

TEST_F(GuiCliTest, DirectAndInverseKinematicsMoveTheHead) {
  ASSERT_GT(gui_->port(), 0) << gui_->output();
  Client client(*gui_);
  json reply = client.Command({{"type", "joints"}, {"positions", {{"pan", 0.2}, {"tilt", 0.05}}}});
  ASSERT_EQ(reply["type"], "reply") << reply;
  EXPECT_DOUBLE_EQ(reply["targets"]["pan"].get<double>(), 0.2);
  EXPECT_EQ(client.Command({{"type", "step"}, {"count", 40}})["type"], "reply");
  json state = client.State([](const json& s) {
    return !s["joints"].is_null() && s["joints"]["arrived"].get<bool>() &&
           std::abs(s["joints"]["positions"]["pan"].get<double>() - 0.2) < 1e-6;
  });
  EXPECT_NEAR(state["joints"]["positions"]["tilt"].get<double>(), 0.05, 1e-6);
  EXPECT_FALSE(state["perception"].get<bool>());

  // Fixate the cat's picture: both optical axes end on the point.
  const json scene = json::parse(Get(*gui_, "/api/scene").body());
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  for (const json& o : scene["objects"]) {
    if (o["name"] == "chelsea") p_W = Matrix(o["X_WO"]).block<3, 1>(0, 3);
  }
  reply = client.Command({{"type", "fixate"}, {"p_W", {p_W.x(), p_W.y(), p_W.z()}}});
  ASSERT_EQ(reply["type"], "reply") << reply;
  EXPECT_LT(reply["axis_error_deg"].get<double>(), 1e-3);
  EXPECT_EQ(client.Command({{"type", "step"}, {"count", 60}})["type"], "reply");
  state = client.State([](const json& s) {
    return s["joints"]["arrived"].get<bool>() && s["joints"]["positions"]["pan"] != 0.2;
  });
  EXPECT_LT(AxisErrorDeg(state, "left", p_W), 0.05);
  EXPECT_LT(AxisErrorDeg(state, "right", p_W), 0.05);
  EXPECT_TRUE(state["fixation_W"].is_array());
}

TEST_F(GuiCliTest, SwitchesEffectsAndStreamsJpegFrames) {
  ASSERT_GT(gui_->port(), 0) << gui_->output();
  Client client(*gui_);
  json error = client.Command({{"type", "effects"}, {"noise", "off"}});
  EXPECT_EQ(error["error"], "effects: field 'noise' must be a boolean, got string");
  error = client.Command({{"type", "effects"}, {"color", 0}});
  EXPECT_EQ(error["error"], "effects: field 'color' must be a boolean, got 0");
  json reply = client.Command({{"type", "effects"}, {"noise", false}, {"color", false}});
  ASSERT_EQ(reply["type"], "reply");
  EXPECT_EQ(reply["effects"]["color"], false) << reply;
  EXPECT_EQ(reply["effects"]["optics"], true) << reply;
  EXPECT_EQ(client.Command({{"type", "step"}, {"count", 2}})["type"], "reply");
  const json state = client.State([](const json& s) { return !s["effects"]["noise"].get<bool>(); });
  EXPECT_TRUE(state["effects"]["distortion"].get<bool>());
  EXPECT_FALSE(state["effects"]["color"].get<bool>());
  // Frames: [4-byte length][JSON header][JPEG].
  while (client.binary().empty()) client.Command({{"type", "step"}});
  const std::string& frame = client.binary().front();
  ASSERT_GT(frame.size(), 4u);
  uint32_t n = 0;
  std::memcpy(&n, frame.data(), 4);
  const json header = json::parse(frame.substr(4, n));
  EXPECT_EQ(header["type"], "frame");
  EXPECT_TRUE(header["camera"] == "left" || header["camera"] == "right");
  EXPECT_EQ(header["width"], 1024);
  EXPECT_EQ(static_cast<unsigned char>(frame[4 + n]), 0xFF);  // JPEG's SOI marker
  EXPECT_EQ(static_cast<unsigned char>(frame[5 + n]), 0xD8);
}

TEST_F(GuiCliTest, PerceptionSwitchedOnFindsTheFaceAndFixatesIt) {
  ASSERT_GT(gui_->port(), 0) << gui_->output();
  Client client(*gui_);
  json reply = client.Command({{"type", "perception"}, {"enabled", "yes"}});
  EXPECT_EQ(reply["error"], "perception: field 'enabled' must be a boolean, got string");
  reply = client.Command({{"type", "perception"}, {"enabled", true}});
  ASSERT_EQ(reply["type"], "reply") << reply;
  EXPECT_EQ(client.Command({{"type", "step"}, {"count", 100}})["type"], "reply");
  // The loop finds the astronaut's face, triangulates it and turns both eyes to it.
  const json state = client.State([](const json& s) {
    return s["perception"].get<bool>() && !s["target"].is_null() &&
           !s["fixation_error_deg"].is_null() &&
           s["fixation_error_deg"]["left"].get<double>() < 0.5 &&
           s["fixation_error_deg"]["right"].get<double>() < 0.5;
  });
  const Eigen::Vector3d p_W(state["target"]["p_W"][0].get<double>(),
                            state["target"]["p_W"][1].get<double>(),
                            state["target"]["p_W"][2].get<double>());
  EXPECT_LT(AxisErrorDeg(state, "left", p_W), 0.5);
  // A hand command takes the head back from the loop.
  reply = client.Command({{"type", "joints"}, {"positions", {{"pan", 0.0}}}});
  EXPECT_FALSE(reply["perception"].get<bool>());
  EXPECT_EQ(client.Command({{"type", "step"}})["type"], "reply");
  // (WaitFor fails the test when no such state comes.)
  const json manual = client.State([](const json& s) { return !s["perception"].get<bool>(); });
  EXPECT_TRUE(manual["target"].is_null());  // no stale target drawn while the loop is off
}

TEST(GuiCli, DemoWithTheGuiRunsTheLoopUntilStoppedThenReports) {
  GuiProcess demo({"demo", "--gui", "--scene", kScene, "--port", "0"});
  ASSERT_GT(demo.port(), 0) << demo.output();
  Client client(demo);
  const json hello = client.WaitFor([](const json& m) { return m["type"] == "hello"; });
  EXPECT_EQ(hello["mode"], "demo");
  // Perception is on from the start: the loop fixates the astronaut by itself. The GUI's run
  // is live, so detection runs on a thread of its own and its faces come some steps late (how
  // many depends on the machine's load). The state shows the eyes on the target first; the
  // report counts the fixation once attention says the eyes are on it, and the demo prints it
  // then: wait for that line (stopped at a fixed time after the first, a busy machine once
  // stopped it before attention had said so).
  client.State([](const json& s) {
    return s["perception"].get<bool>() && !s["fixation_error_deg"].is_null() &&
           s["fixation_error_deg"]["left"].get<double>() < 0.5;
  });
  ASSERT_TRUE(demo.ReadUntil("fixated astronaut", std::chrono::seconds(120))) << demo.output();
  const json state = client.State();
  EXPECT_FALSE(state["paused"].get<bool>());
  EXPECT_EQ(demo.Stop(), 0);
  EXPECT_THAT(demo.output(), HasSubstr("1 of 1 faces fixated"));
  EXPECT_THAT(demo.output(), HasSubstr("images encoded"));
}

// `saccade gui --dds` attaches to a robot running in another process (pipelines/robot.yaml
// under `saccade run`), on loopback in a DDS domain of its own: the robot's images and joint
// states reach the page, and the page's commands move the robot's head.
TEST(GuiCli, DdsAttachesToARobotInAnotherProcessAndDrivesItsHead) {
  setenv("CYCLONEDDS_URI", "file://" SACCADE_SOURCE_DIR "/config/dds/loopback.xml", 0);
  saccade::e2e::BackgroundProcess robot({SACCADE_BINARY, "run", kSource + "/pipelines/robot.yaml",
                                         "--realtime", "--steps", "0", "--dds-domain", "213"});
  ASSERT_TRUE(robot.started());
  GuiProcess gui({"gui", "--dds", "--dds-domain", "213", "--port", "0"});
  ASSERT_GT(gui.port(), 0) << gui.output();
  const json scene = json::parse(Get(gui, "/api/scene").body());
  EXPECT_EQ(scene["commands"]["effects"], false) << "the robot's cameras are not rendered here";
  EXPECT_EQ(scene["commands"]["perception"], true);
  Client client(gui);
  // The robot's state, and both eyes' images, from the other process.
  client.State([](const json& s) { return !s["joints"].is_null(); });
  client.State([&client](const json&) {
    int left = 0, right = 0;
    for (const std::string& frame : client.binary()) {
      uint32_t n = 0;
      std::memcpy(&n, frame.data(), 4);
      const json header = json::parse(frame.substr(4, n));
      left += header["camera"] == "left";
      right += header["camera"] == "right";
    }
    return left >= 2 && right >= 2;
  });
  // A joints command moves the robot's head: the state the robot sends back comes to rest there.
  json reply = client.Command({{"type", "joints"}, {"positions", {{"pan", -0.25}}}});
  ASSERT_EQ(reply["type"], "reply") << reply;
  const json moved = client.State([](const json& s) {
    return !s["joints"].is_null() &&
           std::abs(s["joints"]["positions"]["pan"].get<double>() + 0.25) < 1e-4 &&
           std::abs(s["joints"]["velocities"]["pan"].get<double>()) < 1e-6;
  });
  EXPECT_NEAR(moved["joints"]["positions"]["tilt"].get<double>(), 0.0, 1e-4);
  // Outside the limits: refused here, nothing sent.
  reply = client.Command({{"type", "joints"}, {"positions", {{"pan", 9.0}}}});
  EXPECT_EQ(reply["type"], "error") << reply;
  EXPECT_EQ(gui.Stop(), 0) << gui.output();
  EXPECT_THAT(gui.output(), HasSubstr("remote.cameras"));
}

// The handshake's HTTP status for a raw WebSocket to `target` naming `host` and `origin`, as a
// page of another origin (or a DNS-rebinding page) would open it; 101 when it opened.
int WebSocketStatus(const GuiProcess& gui, const std::string& target, const std::string& host,
                    const std::string& origin) {
  asio::io_context io;
  websocket::stream<tcp::socket> ws(io);
  ws.next_layer().connect(
      tcp::endpoint(asio::ip::make_address("127.0.0.1"), static_cast<uint16_t>(gui.port())));
  ws.set_option(websocket::stream_base::decorator(
      [origin](websocket::request_type& req) { req.set(http::field::origin, origin); }));
  websocket::response_type response;
  beast::error_code ec;
  // (Boost 1.74's synchronous handshake leaves `response` empty when the upgrade is declined.)
  ws.async_handshake(response, host, target, [&ec](beast::error_code e) { ec = e; });
  io.run();
  if (!ec) {
    // Opened: what the attack was after. Send it, so that a regression shows as a moved head.
    ws.text(true);
    ws.write(
        asio::buffer(std::string(R"({"type": "joints", "id": 1, "positions": {"pan": 0.3}})")));
  }
  return response.result_int();
}

TEST_F(GuiCliTest, APageOfAnotherOriginCannotDriveTheHead) {
  ASSERT_GT(gui_->port(), 0) << gui_->output();
  // A random token per run on loopback, in the printed address.
  ASSERT_EQ(gui_->token().size(), 32u) << gui_->output();
  Client client(*gui_);
  EXPECT_EQ(client.Command({{"type", "step"}})["type"], "reply");
  const double pan_before = client.State()["joints"]["targets"]["pan"].get<double>();
  const std::string port = std::to_string(gui_->port());
  // The attack as reported: Host and Origin of the foreign page. Even with the token (which
  // such a page cannot know), the Host and the Origin refuse it.
  EXPECT_EQ(WebSocketStatus(*gui_, gui_->WithToken("/ws"), "evil.example.com:" + port,
                            "http://evil.example.com"),
            403);
  // A page elsewhere that opens ws://127.0.0.1:PORT: the Host is ours, its Origin is not.
  EXPECT_EQ(WebSocketStatus(*gui_, gui_->WithToken("/ws"), "127.0.0.1:" + port,
                            "http://evil.example.com"),
            403);
  // Our own origin without the token: 401.
  EXPECT_EQ(WebSocketStatus(*gui_, "/ws", "127.0.0.1:" + port, "http://127.0.0.1:" + port), 401);
  // A DNS-rebinding page reading the scene.
  EXPECT_EQ(Get(*gui_, "/api/scene", "evil.example.com:" + port).result_int(), 403);
  EXPECT_EQ(Get(*gui_, "/", "evil.example.com:" + port).result_int(), 403);
  // Nothing moved: a step later the pan target is what it was.
  EXPECT_EQ(client.Command({{"type", "step"}})["type"], "reply");
  EXPECT_EQ(client.State()["joints"]["targets"]["pan"].get<double>(), pan_before);
  // The page's own origin with the token opens.
  EXPECT_EQ(WebSocketStatus(*gui_, gui_->WithToken("/ws"), "127.0.0.1:" + port,
                            "http://127.0.0.1:" + port),
            101);
}

TEST_F(GuiCliTest, EachRunHasItsOwnTokenAndNoTokenServesWithout) {
  ASSERT_GT(gui_->port(), 0) << gui_->output();
  EXPECT_EQ(Get(*gui_, "/api/scene").result_int(), 200);
  GuiProcess bare({"gui", "--scene", kScene, "--port", "0", "--paused", "--no-token"});
  ASSERT_GT(bare.port(), 0) << bare.output();
  EXPECT_EQ(bare.token(), "") << bare.output();
  EXPECT_EQ(Get(bare, "/api/scene").result_int(), 200);
  GuiProcess second({"gui", "--scene", kScene, "--port", "0", "--paused"});
  ASSERT_GT(second.port(), 0) << second.output();
  ASSERT_EQ(second.token().size(), 32u) << second.output();
  EXPECT_NE(second.token(), gui_->token());
  // The first run's token does not open the second.
  EXPECT_EQ(GetRaw(second.port(), "/api/scene?token=" + gui_->token()).result_int(), 401);
  EXPECT_EQ(GetRaw(second.port(), "/api/scene").result_int(), 401);
}

TEST(GuiCli, NoTokenIsRefusedBeyondLoopback) {
  const saccade::e2e::CommandRun run =
      saccade::e2e::Saccade("gui --scene " + kScene + " --listen 0.0.0.0 --port 0 --no-token");
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr("--no-token is for loopback addresses only"));
}

TEST(GuiCli, RefusesToListenBeyondLoopbackWithoutAToken) {
  const saccade::e2e::CommandRun run =
      saccade::e2e::Saccade("gui --scene " + kScene + " --listen 0.0.0.0 --port 0");
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_THAT(run.output, HasSubstr("token"));
}

}  // namespace
