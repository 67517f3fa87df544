#pragma once
// ROS 2 names on the DDS wire (rmw_cyclonedds's conventions, design.ros2.org "Topic and
// Service name mapping to DDS"): a ROS topic /saccade/left/image_raw is the DDS topic
// rt/saccade/left/image_raw; its type sensor_msgs/msg/Image is the DDS type
// sensor_msgs::msg::dds_::Image_.
#include <string>

namespace saccade::dds {

/// The fully qualified ROS 2 name of `name`: an absolute name ("/joint_states") as it is, a
/// relative one ("left/image_raw") under `ns` ("/saccade" gives "/saccade/left/image_raw";
/// "" or "/" the root). Both follow ROS 2's rules: tokens of letters, digits and '_' separated
/// by single '/', no token starting with a digit, no trailing '/', no '~' or '{}'
/// substitutions. Throws InvalidArgument naming the name, the offending character or token,
/// and the rule.
std::string ResolveTopic(const std::string& name, const std::string& ns = "");

/// The DDS topic of a fully qualified ROS topic: "rt" + name ("rt/saccade/left/image_raw").
/// Throws InvalidArgument when `ros_topic` is not fully qualified and valid.
std::string DdsTopicName(const std::string& ros_topic);

/// The ROS topic beside `ros_topic` named `sibling`: "/saccade/left/image_raw" and
/// "camera_info" give "/saccade/left/camera_info" (a camera's info lives next to its image).
std::string SiblingTopic(const std::string& ros_topic, const std::string& sibling);

}  // namespace saccade::dds
