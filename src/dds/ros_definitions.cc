// The ROS 2 message definitions of the types saccade's writers produce (topics.h:
// RosMessageDefinition), as their .msg files in ros2/common_interfaces, ros2/rcl_interfaces and
// ros2/geometry2 declare the fields (comments left out, every type named with its package).
#include <fmt/format.h>

#include <map>
#include <set>
#include <string>
#include <vector>

#include "saccade/core/error.h"
#include "saccade/dds/topics.h"

namespace saccade::dds {
namespace {

// "pkg/Type" (as .msg files name types) -> its fields.
const std::map<std::string, std::string>& Definitions() {
  static const std::map<std::string, std::string> definitions = {
      {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
      {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
      {"std_msgs/String", "string data\n"},
      {"sensor_msgs/Image",
       "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\n"
       "uint8 is_bigendian\nuint32 step\nuint8[] data\n"},
      {"sensor_msgs/CompressedImage", "std_msgs/Header header\nstring format\nuint8[] data\n"},
      {"sensor_msgs/RegionOfInterest",
       "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n"},
      {"sensor_msgs/CameraInfo",
       "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\n"
       "float64[] d\nfloat64[9] k\nfloat64[9] r\nfloat64[12] p\nuint32 binning_x\n"
       "uint32 binning_y\nsensor_msgs/RegionOfInterest roi\n"},
      {"sensor_msgs/JointState",
       "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
       "float64[] effort\n"},
      // Constants as the .msg file declares them (rosbag2 stores them with the fields).
      {"sensor_msgs/PointField",
       "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\n"
       "uint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\n"
       "uint8 datatype\nuint32 count\n"},
      {"sensor_msgs/PointCloud2",
       "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n"
       "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n"},
      {"geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/PointStamped", "std_msgs/Header header\ngeometry_msgs/Point point\n"},
      {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"},
      {"geometry_msgs/Transform",
       "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n"},
      {"geometry_msgs/TransformStamped",
       "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n"},
      {"tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms\n"},
      {"rosgraph_msgs/Clock", "builtin_interfaces/Time clock\n"},
  };
  return definitions;
}

// The types a definition's fields use, in the order they first appear.
std::vector<std::string> UsedTypes(const std::string& fields) {
  std::vector<std::string> used;
  std::size_t line = 0;
  while (line < fields.size()) {
    const std::size_t end = fields.find('\n', line);
    std::string type = fields.substr(line, fields.find(' ', line) - line);
    if (const auto bracket = type.find('['); bracket != std::string::npos) type.resize(bracket);
    if (type.find('/') != std::string::npos) used.push_back(type);
    line = end == std::string::npos ? fields.size() : end + 1;
  }
  return used;
}

void AddDependencies(const std::string& type, std::set<std::string>& seen,
                     std::vector<std::string>& order) {
  for (const std::string& used : UsedTypes(Definitions().at(type))) {
    if (seen.insert(used).second) {
      order.push_back(used);
      AddDependencies(used, seen, order);
    }
  }
}

}  // namespace

std::string RosMessageDefinition(const std::string& ros_type) {
  // "sensor_msgs/msg/Image" -> "sensor_msgs/Image"
  const auto at = ros_type.find("/msg/");
  const std::string type =
      at == std::string::npos ? ros_type : ros_type.substr(0, at) + "/" + ros_type.substr(at + 5);
  const auto found = Definitions().find(type);
  if (found == Definitions().end()) {
    throw InvalidArgument("dds: no ROS 2 message definition of '" + ros_type +
                          "' (saccade writes " + "sensor_msgs, geometry_msgs, tf2_msgs, std_msgs " +
                          "and rosgraph_msgs types only)");
  }
  std::string text = found->second;
  std::set<std::string> seen{type};
  std::vector<std::string> order;
  AddDependencies(type, seen, order);
  for (const std::string& used : order) {
    text += fmt::format("{:=<80}\nMSG: {}\n{}", "", used, Definitions().at(used));
  }
  return text;
}

}  // namespace saccade::dds
