#include "saccade/dds/topic_names.h"

#include <fmt/format.h>

#include <cctype>

#include "saccade/core/error.h"

namespace saccade::dds {
namespace {

// Checks a fully qualified ROS 2 name (design.ros2.org/articles/topic_and_service_names.html).
void CheckQualified(const std::string& name, const std::string& given) {
  const auto Fail = [&](const std::string& why) {
    throw InvalidArgument(fmt::format("topic '{}': {}", given, why));
  };
  if (name.empty() || name[0] != '/') Fail("a ROS topic name must start with '/' once resolved");
  if (name.size() == 1) Fail("the root '/' is not a topic");
  if (name.back() == '/') Fail("a ROS topic name must not end with '/'");
  std::size_t start = 1;
  while (start <= name.size()) {
    const std::size_t end = std::min(name.find('/', start), name.size());
    const std::string token = name.substr(start, end - start);
    if (token.empty()) Fail("empty token ('//'): tokens are separated by single '/'");
    if (std::isdigit(static_cast<unsigned char>(token[0]))) {
      Fail(fmt::format("token '{}' starts with a digit", token));
    }
    for (const char c : token) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') {
        Fail(fmt::format("character '{}' is not allowed: tokens are letters, digits and '_'", c));
      }
    }
    start = end + 1;
  }
  // DDS topic names are bounded (rmw: 255 characters including "rt").
  if (name.size() + 2 > 255) Fail("longer than the 253 characters ROS 2 allows");
}

}  // namespace

std::string ResolveTopic(const std::string& name, const std::string& ns) {
  if (name.empty()) throw InvalidArgument("topic '': a topic name must not be empty");
  if (name[0] == '~' || name.find('{') != std::string::npos) {
    throw InvalidArgument(
        fmt::format("topic '{}': '~' and '{{}}' substitutions are not supported; give the full "
                    "name or one relative to the namespace",
                    name));
  }
  std::string full = name;
  if (name[0] != '/') {
    std::string prefix = ns;
    if (!prefix.empty() && prefix[0] != '/') prefix = "/" + prefix;
    while (prefix.size() > 1 && prefix.back() == '/') prefix.pop_back();  // "/saccade/" too
    if (prefix.size() > 1) CheckQualified(prefix, ns);
    if (prefix == "/") prefix.clear();
    full = prefix + "/" + name;
  }
  CheckQualified(full, name);
  return full;
}

std::string DdsTopicName(const std::string& ros_topic) {
  CheckQualified(ros_topic, ros_topic);
  return "rt" + ros_topic;
}

std::string SiblingTopic(const std::string& ros_topic, const std::string& sibling) {
  const std::size_t slash = ros_topic.rfind('/');
  return ros_topic.substr(0, slash == std::string::npos ? 0 : slash) + "/" + sibling;
}

}  // namespace saccade::dds
