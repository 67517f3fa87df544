// The loop's messages: JSON forms that round-trip, and errors that name the field.
#include "saccade/components/messages.h"

#include <gtest/gtest.h>

#include <memory>

#include "saccade/core/error.h"

namespace saccade::components {
namespace {

using runtime::MessageTraits;

template <typename T>
void ExpectRoundTrip(const T& message) {
  const nlohmann::json j = MessageTraits<T>::ToJson(message);
  const T back = MessageTraits<T>::FromJson(j);
  EXPECT_EQ(MessageTraits<T>::ToJson(back), j) << j.dump();
  // Through the registry by name, as a text link would.
  RegisterMessages();
  const runtime::MessageType* type =
      runtime::MessageRegistry::Global().Find(MessageTraits<T>::kName);
  ASSERT_NE(type, nullptr) << MessageTraits<T>::kName;
  EXPECT_EQ(type->to_json(type->from_json(j).get()), j);
}

TEST(Messages, EveryTypeRoundTripsThroughJson) {
  JointStateMessage joints;
  joints.time = 1.25;
  joints.positions = head::JointState::Popeye(0.1, -0.2, -0.03, 0.03);
  joints.velocities = head::JointState::Popeye(1.0, 0.0, -0.5, 0.5);
  joints.targets = head::JointState::Popeye(0.2, -0.2, -0.04, 0.04);
  joints.arrived = false;
  joints.clamped_commands = 2;
  ExpectRoundTrip(joints);

  JointCommand command;
  command.time = 0.5;
  command.positions = head::JointState::Popeye(0.3, 0.1, -0.05, 0.05);
  command.velocities = head::JointState::Popeye(0.1, 0.0, 0.0, 0.0);
  command.target_id = 4;
  EXPECT_TRUE(command.pursuit());
  ExpectRoundTrip(command);

  HeadStatusMessage status;
  status.time = 3.5;
  status.driver = "dynamixel on /tmp/saccade-servos";
  status.positions = head::JointState::Popeye(0.1, 0.0, -0.02, 0.02);
  status.torque = true;
  status.holding = true;
  status.fault = "servo 2 (tilt): overload";
  status.commands = 40;
  status.rejected_commands = 3;
  status.watchdog_trips = 1;
  status.last_limit = "pan target 120.00 deg clamped to 90.00 deg";
  ExpectRoundTrip(status);

  auto image = std::make_shared<Image>(8, 6, PixelFormat::kRgb8);
  image->metadata().camera = "left";
  image->metadata().frame_index = 12;
  FacesMessage faces;
  faces.image = image;
  faces.faces.push_back({cv::Rect(10, 20, 90, 95), 31, false, ""});
  faces.faces.push_back({cv::Rect(300, 20, 60, 60), 4, true, "cat face"});
  const nlohmann::json faces_json = MessageTraits<FacesMessage>::ToJson(faces);
  EXPECT_EQ(faces_json["image"]["camera"], "left");  // metadata only, never pixels
  EXPECT_EQ(faces_json["image"]["frame_index"], 12);
  EXPECT_FALSE(faces_json["image"].contains("pixels"));
  EXPECT_EQ(MessageTraits<FacesMessage>::FromJson(faces_json).faces.size(), 2u);

  CandidatesMessage candidates;
  candidates.time = 2.0;
  candidates.frame_index = 50;
  candidates.candidates.push_back({Eigen::Vector3d(2.2, 0.35, 1.2), cv::Rect(1, 2, 3, 4),
                                   cv::Rect(5, 6, 7, 8), 2.25, 0.4, 0.001, 0.17});
  ExpectRoundTrip(candidates);

  SelectionMessage selection;
  selection.valid = true;
  selection.target_id = 3;
  selection.p_W = {1.0, 2.0, 3.0};
  selection.fixating = true;
  selection.dwell_s = 0.5;
  selection.suppressed_W = {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(2, 2, 2)};
  ExpectRoundTrip(selection);

  TrackMessage track;
  track.target_id = 3;
  track.tracking = true;
  track.window = {40, 50, 60, 70};
  track.center = {70.5, 85.5};
  ExpectRoundTrip(track);

  TargetMessage target;
  target.valid = true;
  target.target_id = 3;
  target.p_W = {2.0, 0.1, 1.1};
  target.source = "tracks";
  ExpectRoundTrip(target);

  DepthMessage depth;
  depth.time = 3.0;
  depth.frame_index = 75;
  depth.left = image;
  depth.stereo = std::make_shared<vision::StereoDepth>();
  depth.matched = 0.83;
  depth.baseline_m = 0.2;
  depth.focal_px = 645.1;
  const nlohmann::json depth_json = MessageTraits<DepthMessage>::ToJson(depth);
  EXPECT_EQ(depth_json["left"]["frame_index"], 12);  // the image's metadata, never pixels
  EXPECT_FALSE(depth_json.contains("stereo"));
  EXPECT_EQ(MessageTraits<DepthMessage>::FromJson(depth_json).stereo, nullptr);
  EXPECT_DOUBLE_EQ(MessageTraits<DepthMessage>::FromJson(depth_json).matched, 0.83);

  MapMessage map;
  map.time = 4.0;
  map.frame_index = 100;
  map.resolution_m = 0.02;
  map.occupied_W = {Eigen::Vector3d(2.01, 0.03, 1.05), Eigen::Vector3d(2.01, 0.05, 1.05)};
  map.inhibited.push_back({Eigen::Vector3d(2.0, 0.0, 1.0), 0.3, 0.75});
  map.fused = 12;
  ExpectRoundTrip(map);
}

TEST(Messages, BadJsonNamesTheTypeAndTheField) {
  nlohmann::json j = runtime::MessageTraits<JointCommand>::ToJson(JointCommand{});
  j["positions"]["tilt"] = "up";
  try {
    runtime::MessageTraits<JointCommand>::FromJson(j);
    FAIL() << "accepted a string angle";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "head.command.positions: field 'tilt': expected a number, got \"up\"");
  }
  nlohmann::json faces = {{"faces", {{{"box", {1, 2, -3, 4}}}}}};
  try {
    runtime::MessageTraits<FacesMessage>::FromJson(faces);
    FAIL() << "accepted a negative width";
  } catch (const Error& e) {
    // The path names the element of the list.
    EXPECT_STREQ(e.what(),
                 "vision.faces.faces[0]: field 'box': expected [x, y, width, height] in whole "
                 "pixels, width and height >= 0, got [1,2,-3,4]");
  }
}

}  // namespace
}  // namespace saccade::components
