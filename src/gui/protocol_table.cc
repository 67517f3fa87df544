// The GUI protocol's table (protocol.h): every message each way, declared once. The session
// checks commands and its own messages against it; docs/gui-protocol.md and
// web/public/app/protocol.js are generated from it (`saccade gui --protocol-markdown`,
// `--protocol-js`).
#include <fmt/format.h>

#include <utility>

#include "saccade/gui/protocol.h"
#include "saccade/server/gui_server.h"

namespace saccade::gui::protocol {
namespace {

using nlohmann::json;

// The frame window's bound, as the server module enforces it (server/internal_server_core.h's
// kMaxFrameWindow; tests/gui/protocol_test.cc holds them equal).
constexpr double kMaxFrameWindow = 64;

Schema Pose() {
  const Schema row = Array(Number(), 4);
  return Named("pose", Tuple({row, row, row, Tuple({Const(0), Const(0), Const(0), Const(1)})}));
}
Schema Point() { return Named("point", Array(Number(), 3)); }
constexpr const char* kAnyJoint = "a joint (scene.head.joints)";

// Joint name -> value: every actuated joint of the head (`scene.head.joints`; POPEYE's are
// pan, tilt, left and right).
Schema Joints() {
  Schema joints = Object({});
  joints.open = true;
  joints.others = kAnyJoint;
  joints.items = {Number()};
  return Named("joints", joints);
}
// Link name -> pose: every link of the head's tree (`scene.robot.links`).
Schema LinkPoses() {
  Schema links = Object({});
  links.open = true;
  return links;
}
Schema Rgb() { return Named("rgb", Array(Number(), 3)); }
Schema Rgba() { return Named("rgba", Array(Number(), 4)); }
Schema Effects() {
  return Named(
      "effects",
      Object({Required("distortion", Boolean(), "lens distortion"),
              Required("noise", Boolean(), "sensor noise"),
              Required("motion_blur", Boolean(), "motion blur"),
              Required("optics", Boolean(), "the lens's vignetting and depth of field"),
              Required("color", Boolean(),
                       "the colour filter array, demosaicing, white balance and tone curve")}));
}

// A command: {"type", "id"} and `fields`; its reply adds `reply`.
Message Command(std::string type, std::string summary, std::vector<Field> fields,
                std::vector<Field> reply, std::string doc = "") {
  std::vector<Field> body = {
      Required("type", Const(type), "the command"),
      Required("id", Integer(), "grows with each command of the connection")};
  body.insert(body.end(), fields.begin(), fields.end());
  Message m;
  m.type = std::move(type);
  m.channel = Channel::kCommand;
  m.summary = std::move(summary);
  m.doc = std::move(doc);
  m.body = Object(std::move(body));
  m.reply = std::move(reply);
  return m;
}

// A message of the server: {"type"} and `fields`.
Message ServerMessage(std::string type, Channel channel, std::string summary,
                      std::vector<Field> fields, std::string doc = "") {
  fields.insert(fields.begin(), Required("type", Const(type), "the message"));
  Message m;
  m.type = std::move(type);
  m.channel = channel;
  m.summary = std::move(summary);
  m.doc = std::move(doc);
  m.body = Object(std::move(fields));
  return m;
}

Field ManualReply() {
  return Required("perception", Const(false), "perception is off: the hand overrides the loop");
}

std::vector<Field> FlowReply() {
  return {Required("window", Integer(0, kMaxFrameWindow), "the client's frame window now"),
          Required("frames_sent", Integer(0), "frames sent to this client so far"),
          Required("frames_acked", Integer(0), "the client's running total acknowledged")};
}

void AddMotionCommands(std::vector<Message>& out) {
  Schema positions = Object(
      {Optional("vergence", Number(),
                "rad, the head's symmetric pair (a, b, sign) of `scene.head.symmetric` (POPEYE: "
                "left = -v, right = +v; v > 0 converges), unless the head has a joint of that "
                "name")});
  positions.open = true;  // any joint of `scene.head.joints`, by name
  positions.others = kAnyJoint;
  positions.items = {Number()};
  positions.some = true;
  out.push_back(
      Command("joints", "direct kinematics: moves those joints (the others keep their targets)",
              {Required("positions", positions, "the joints to move and their targets")},
              {Required("targets", Joints(), "every joint's target now (rad)"), ManualReply()},
              "`positions` names joints of `scene.head.joints` (rad, or m for a prismatic "
              "joint); an unknown name, a joint the head does not drive, or a value outside its "
              "limits refuses the whole command, checked on the server. Turns perception off "
              "(manual)."));
  out.push_back(Command("fixate",
                        "inverse kinematics: both optical axes through the point, by the head's "
                        "fixation rule",
                        {Required("p_W", Point(), "the point, metres in the world frame")},
                        {Required("targets", Joints(), "every joint's target now (rad)"),
                         Required("axis_error_deg", Number(0),
                                  "each optical axis to the point at the solution (deg)"),
                         ManualReply()},
                        "Unreachable points are refused with the reason. Turns perception off."));
}

void AddHeadCommands(std::vector<Message>& out) {
  out.push_back(
      Command("stop", "brakes every joint and holds; turns perception off", {}, {ManualReply()}));
  out.push_back(Command("estop",
                        "emergency stop (hw.head only; else an error); turns perception off", {},
                        {ManualReply()}));
  out.push_back(Command("clear", "clears the emergency stop (hw.head only; else an error)", {},
                        {ManualReply()}));
}

void AddSimulationCommands(std::vector<Message>& out) {
  out.push_back(
      Command("perception", "the perception loop commands the head (true) or not",
              {Optional("enabled", Boolean(), "on or off (missing: as it is)")},
              {Required("perception", Boolean(), "whether the loop commands the head now")}));
  Message effects =
      Command("effects", "the simulated cameras' effects (an error when the cameras are real)",
              {Optional("distortion", Boolean(), "lens distortion (missing: as it is)"),
               Optional("noise", Boolean(), "sensor noise (missing: as it is)"),
               Optional("motion_blur", Boolean(), "motion blur (missing: as it is)"),
               Optional("optics", Boolean(),
                        "the lens's vignetting and depth of field (missing: as it is)"),
               Optional("color", Boolean(),
                        "the sensor's colour filter array, demosaicing, white balance and tone "
                        "curve (missing: as it is)")},
              {Required("effects", Effects(), "the effects now")});
  out.push_back(std::move(effects));
  out.push_back(Command("pause", "stops the simulation clock", {},
                        {Required("paused", Const(true), "paused")}));
  out.push_back(Command("resume", "restarts the simulation clock", {},
                        {Required("paused", Const(false), "running")}));
  out.push_back(Command("step", "while paused: runs that many steps",
                        {Optional("count", Integer(1, 1000), "steps (missing: 1)")},
                        {Required("steps", Integer(1, 1000), "the steps it runs")}));
  out.push_back(Command(
      "record",
      "starts (true) or stops (false) recording every topic to an MCAP file in the server's "
      "recording folder (`saccade gui --record-dir`), named by the server; an error when it has "
      "none",
      {Required("enabled", Boolean(), "record or stop")},
      {Required("recording", Boolean(), "as asked: the state's `recording` says when it is")}));
  out.push_back(Command("speed",
                        "the pace: simulated seconds per wall second, at most (best effort)",
                        {Required("factor", Number(0.05, 10), "simulated s per wall s")},
                        {Required("speed", Number(0.05, 10), "the pace now")}));
}

void AddConnectionCommands(std::vector<Message>& out) {
  out.push_back(Command("ping", "latency measurement", {},
                        {Required("time", Number(), "the simulation's time (s)")}));
  Message window =
      Command("frame_window", "flow control of camera frames (below)",
              {Required("frames", Integer(0, kMaxFrameWindow),
                        "at most this many frames sent and not acknowledged; 0: no window")},
              FlowReply());
  window.transport = true;
  out.push_back(std::move(window));
  Message ack = Command(
      "frame_ack", "flow control: the frames this client has finished with",
      {Required("frames", Integer(0),
                "the running total since connecting (shown, dropped or not wanted); it never "
                "decreases nor exceeds the frames sent")},
      FlowReply());
  ack.transport = true;
  out.push_back(std::move(ack));
}

Message State() {
  const Schema frames = Object(
      {Required("X_WB", Pose(), "the head's base (its tree's root link)"),
       Required("X_WC", Pose(), "midway between the optical centres, the base's axes"),
       Required("links", LinkPoses(), "every link of the tree by name (robot parts hang here)"),
       Required("left", Pose(), "the left camera's optical frame (OpenCV axes)"),
       Required("right", Pose(), "the right camera's optical frame")});
  const Schema target = Object({Required("valid", Const(true), "always true when present"),
                                Required("p_W", Point(), "where perception puts it"),
                                Required("id", Integer(), "the attended target's id")});
  const Schema timing =
      Object({Required("step_ms", Number(0), "wall time of the last step (ms)"),
              Required("steps_per_s", Number(0), "steps per wall second, recently"),
              Required("realtime_factor", Number(0), "simulated seconds per wall second, recently"),
              Required("frames_per_s", Number(0), "images encoded per second, recently")});
  Schema head_status = OrNull(Object({}));
  head_status.open = true;
  return ServerMessage(
      "state", Channel::kText,
      "the simulation after a step, up to once per step (a slow client gets only the newest)",
      {Required("step", Integer(0), "the steps taken"),
       Required("time", Number(), "the simulation's time after the step (s)"),
       Required("paused", Boolean(), "the clock is stopped"),
       Required("speed", Number(0.05, 10), "simulated seconds per wall second, at most"),
       Required("perception", Boolean(), "the perception loop commands the head"),
       Required("manual", Boolean(), "the hand commands the head (not perception)"),
       Required("effects", OrNull(Effects()), "the cameras' effects; null when they are real"),
       Required("joints",
                OrNull(Object({Required("positions", Joints(), "rad"),
                               Required("targets", Joints(), "rad"),
                               Required("velocities", Joints(), "rad/s"),
                               Required("arrived", Boolean(), "every joint on its target")})),
                "the head's joints; null without a head"),
       Required("frames", OrNull(frames), "the head's frames (forward kinematics)"),
       Required("fixation_W", OrNull(Point()), "where the optical axes meet; null when they don't"),
       Required("target", OrNull(target), "perception's target; null with perception off"),
       Required("fixation_error_deg",
                OrNull(Object(
                    {Required("left", Number(0), "deg"), Required("right", Number(0), "deg")})),
                "each optical axis to the target"),
       Required("objects",
                Array(Object({Required("name", String(), "the object's name"),
                              Required("X_WO", Pose(), "its pose now")})),
                "the moving objects only"),
       Required("timing", timing, "how fast the loop runs"),
       Required("head_status", head_status,
                "hw.head's head.status message (components/messages.h); null without one"),
       Required("recording",
                OrNull(Object({Required("file", String(), "the MCAP file being written"),
                               Required("megabytes", Number(0), "written so far")})),
                "the recording the page or --record started; null when none")});
}

Message Map() {
  const Schema place =
      Object({Required("p_W", Point(), "the place (m, world)"),
              Required("radius_m", Number(0), "the head does not look within it (m)"),
              Required("strength", Number(0, 1), "1 when fixated, decaying after")});
  return ServerMessage(
      "map", Channel::kText,
      fmt::format("the map a pipeline builds (mapping.map): when it changed, at most once "
                  "every {} steps (a slow client gets only the newest)",
                  kMapEverySteps),
      {Required("time", Number(), "the map's time (s)"),
       Required("frame", Integer(), "the map's frame index"),
       Required("resolution_m", Number(0), "voxel edge (m); 0: not known (a map from DDS)"),
       Required("fused", Integer(0), "depth images fused into it so far"),
       Required("total", Integer(0), "occupied voxels in the map"),
       Required("points", Array(Number()),
                fmt::format("occupied voxels' centres, [x0, y0, z0, x1, ...] (m, world, to the "
                            "mm): every one, or every k-th when there are more than {} (k = "
                            "ceil(total / {}))",
                            kMaxMapPoints, kMaxMapPoints)),
       Required("inhibited", Array(place),
                "the places inhibition of return holds, strongest first")},
      "Sent only by pipelines with a `mapping.map` output (the first one); a client that "
      "connects later gets the newest. The page draws the points coloured by height and the "
      "inhibited places as spheres whose opacity is their strength.");
}

void AddServerMessages(std::vector<Message>& out) {
  out.push_back(ServerMessage(
      "hello", Channel::kText, "the first message on connecting; the newest state follows",
      {Required("protocol", Const(server::kProtocolName), "the protocol's name"),
       Required("version", Const(server::kProtocolVersion), "its version"),
       Required("client", Integer(1), "this connection's number (as in /api/status)"),
       Required("mode", String({"demo", "gui"}), "`saccade demo --gui` or `saccade gui`")}));
  out.push_back(State());
  out.push_back(Map());
  out.push_back(ServerMessage(
      "reply", Channel::kText, "a command was accepted; its fields depend on the command",
      {Required("id", Integer(), "the command's id"), Required("ok", Const(true), "accepted")},
      "The fields each command's reply adds are in the table of commands."));
  out.push_back(ServerMessage(
      "error", Channel::kText, "a command was refused: nothing happened",
      {Required("id", OrNull(Integer()), "the command's id; null when it had no readable one"),
       Required("error", String(), "what was wrong, naming the field")}));
  out.push_back(ServerMessage("event", Channel::kText, "something the operator should know",
                              {Required("level", String({"info", "warning", "error"}), "how bad"),
                               Required("message", String(), "what happened")}));
  out.push_back(ServerMessage(
      "frame", Channel::kFrame, "the JSON header of a camera frame (a binary message)",
      {Required("camera", String(), "the camera's name (the scene's `cameras`)"),
       Required("frame", Integer(), "the image's frame index"),
       Required("time", Number(), "the image's time (s)"), Required("width", Integer(1), "pixels"),
       Required("height", Integer(1), "pixels"),
       Required("overlay", Boolean(),
                "detections (green; rejected red), the CamShift window (yellow) and the target "
                "(cyan) are drawn into the image"),
       Required("exposure_s", Number(0), "the exposure it was taken with (s; 0: an instant)"),
       Required("gain_db", Number(), "the gain it was taken with (dB)"),
       Required("focus_m", Number(0), "the focus distance it was taken with (m; 0: none)")}));
}

Schema Models() {
  return Array(Object(
      {Required("source", String(), "the file the scene loader read"),
       Required("url", String(), "its meshes, binary (/api/models/N.bin)"),
       Required("bounds", Tuple({Point(), Point()}), "[min, max] corners (model frame, metres)"),
       Required("materials",
                Array(Object({Required("base_color", Rgba(), "linear"),
                              Required("texture", OrNull(String()), "/api/textures/N.png"),
                              Required("specular", Number(), "specular strength"),
                              Required("shininess", Number(), "Phong exponent")})),
                "the materials the meshes name"),
       Required("meshes",
                Array(Object({Required("vertices", Integer(0), "V"),
                              Required("indices", Integer(0), "I, three per triangle"),
                              Required("uvs", Boolean(), "the binary holds V x 2 uvs"),
                              Required("material", Integer(0), "index into `materials`")})),
                "in the binary's order")}));
}

Schema Cameras() {
  return Array(Object(
      {Required("width", Integer(1), "pixels"), Required("height", Integer(1), "pixels"),
       Required("K", Array(Array(Number(), 3), 3), "[[fx, s, cx], [0, fy, cy], [0, 0, 1]]"),
       Required("distortion",
                Object({Required("model", String({"none", "radtan", "fisheye"}), "the model"),
                        Required("coefficients", Array(Number()), "its coefficients")}),
                "the lens"),
       Required("name", String(), "the camera's name"),
       Required("eye", String({"left", "right", "world"}), "where it is mounted"),
       Required("X_WC", Pose(), "at time 0; eye cameras move with `state.frames`"),
       Required("near", Number(0), "clip plane (m)"), Required("far", Number(0), "clip plane (m)"),
       Required("optics", Boolean(),
                "its lens has vignetting or depth of field (what the `effects` switch `optics` "
                "changes)"),
       Required("color", Boolean(),
                "its sensor has a colour filter array, white balance or a tone curve (what the "
                "`effects` switch `color` changes)")}));
}

Schema SceneRobot() {
  return OrNull(Object(
      {Required("visible", Boolean(), "the robot's body is drawn"),
       Required("links",
                Array(Object({Required("name", String(), "the link (URDF's name)"),
                              Required("parent", OrNull(String()), "its parent; null: the root"),
                              Required("joint", OrNull(String()),
                                       "the joint to its parent; null: the root")})),
                "the head's kinematic tree, parents first"),
       Required("parts",
                Array(Object(
                    {Required("link", String(), "the link it hangs from (`state.frames.links`)"),
                     Required("model", Integer(-1), "index into `models`; -1: none"),
                     Required("X_LinkPart", Pose(), "the part in its link's frame"),
                     Required("scale", Point(), "per axis")})),
                "the body's parts")}));
}

Message Scene() {
  const Schema ground = Object(
      {Required("enabled", Boolean(), "drawn"), Required("size", Number(0), "side (m)"),
       Required("pattern", String({"plain", "grid", "checker"}), "its pattern"),
       Required("cell", Number(0), "pattern cell (m)"),
       Required("line_width", Number(0), "grid lines (m)"), Required("color", Rgb(), "linear"),
       Required("color2", Rgb(), "the pattern's second")});
  const Schema lights =
      Array(Object({Required("type", String({"ambient", "directional", "point"}), "its kind"),
                    Required("color", Rgb(), "linear"), Required("intensity", Number(0), "scale"),
                    Required("direction", Point(), "directional lights: where the light goes"),
                    Required("position", Point(), "point lights"),
                    Required("attenuation", Number(0), "point lights: quadratic falloff")}));
  const Schema objects = Array(Object(
      {Required("name", String(), "its name"), Required("id", Integer(), "its id (ground truth)"),
       Required("model", Integer(-1), "index into `models`; -1: none"),
       Required("scale", Point(), "per axis"), Required("X_WO", Pose(), "at `time`"),
       Required("moving", Boolean(), "its pose comes in every state")}));
  const Schema joints = Array(
      Object({Required("name", String(), "the joint (URDF's name)"),
              Required("type", String({"revolute", "continuous", "prismatic"}), "its kind"),
              Required("link", String(), "the link it moves (its child)"),
              Required("axis", Point(), "its unit axis in the frame of the link it moves"),
              Required("min", OrNull(Number()), "rad (m); null: unbounded"),
              Required("max", OrNull(Number()), "rad (m); null: unbounded"),
              Required("max_velocity", Number(0), "rad/s (m/s)"),
              Required("driven", Boolean(), "saccade commands it (else held at its value)")}));
  const Schema pair = Tuple({String(), String(), Number()});
  const Schema commands =
      Object({Required("effects", Boolean(), "`effects` (the cameras are simulated)"),
              Required("perception", Boolean(), "`perception` (components besides the robot)"),
              Required("estop", Boolean(), "`estop` and `clear` (a hardware head)")});
  Message m = ServerMessage(
      "scene", Channel::kDocument, "the scene, as the renderer has it (an HTTP GET)",
      {Required("protocol", Const(server::kProtocolName), "the protocol's name"),
       Required("version", Const(server::kProtocolVersion), "its version"),
       Required("mode", String({"demo", "gui"}), "`saccade demo --gui` or `saccade gui`"),
       Required("name", String(), "the scene file's name"),
       Required("time", Number(), "the time of the poses below (s)"),
       Required("background", Rgb(), "linear"), Required("ground", ground, "the ground plane"),
       Required("lights", lights, "the lights"), Required("models", Models(), "each model once"),
       Required("objects", objects, "the scene's objects"),
       Required("robot", SceneRobot(), "the robot's body; null without a robot"),
       Required("head",
                Object({Required("name", String(), "the head's name (\"\" without a robot)"),
                        Required("joints", joints, "the actuated joints, in the head's order"),
                        Required("symmetric", Array(pair),
                                 "pairs [a, b, sign] fixation holds at b = sign * a")}),
                "the head's joints and limits (empty without a robot)"),
       Required("cameras", Cameras(), "every camera of the scene"),
       Required("commands", commands, "which commands this session offers")},
      "Model frames and object frames are z up like the world. Robot parts hang from the "
      "links of the head's tree (`robot.links`), posed in every state (`state.frames.links`).");
  m.body.fields.erase(m.body.fields.begin());  // a document has no "type"
  return m;
}

std::vector<Message> BuildMessages() {
  std::vector<Message> out;
  AddMotionCommands(out);
  AddSimulationCommands(out);
  AddHeadCommands(out);
  AddConnectionCommands(out);
  AddServerMessages(out);
  out.push_back(Scene());
  return out;
}

}  // namespace

const std::vector<Message>& Messages() {
  static const std::vector<Message> messages = BuildMessages();
  return messages;
}

const std::vector<NamedType>& Types() {
  static const std::vector<NamedType> types = {
      {Pose(),
       "a pose: its 4x4 matrix, row by row, `[[r00, r01, r02, x], [r10, r11, r12, y], [r20, r21, "
       "r22, z], [0, 0, 0, 1]]` (metres)"},
      {Point(), "`[x, y, z]`: a point or a vector (metres)"},
      {Joints(),
       "one number per joint of `scene.head.joints`, by name (POPEYE: `{pan, tilt, left, right}`; "
       "rad or m, or rad/s)"},
      {Rgb(), "a linear colour `[r, g, b]`, 0 to 1"},
      {Rgba(), "a linear colour with opacity `[r, g, b, a]`, 0 to 1"},
      {Effects(),
       "the simulated cameras' effects: `{distortion, noise, motion_blur, optics, color}`, "
       "booleans"},
  };
  return types;
}

}  // namespace saccade::gui::protocol
