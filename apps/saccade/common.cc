#include <fmt/format.h>

#include <filesystem>

#include "commands.h"
#include "saccade/core/error.h"

namespace saccade::app {

std::string ShippedFile(const std::string& relative) {
  namespace fs = std::filesystem;
  if (fs::exists(relative)) return relative;
  // The source tree it was built from; else where `cmake --install` put the data.
  const fs::path source = fs::path(SACCADE_SOURCE_DIR) / relative;
  const fs::path installed = fs::path(SACCADE_DATA_DIR) / relative;
  if (!fs::exists(source) && fs::exists(installed)) return installed.string();
  return source.string();
}

head::JointState JointsFromArgs(const head::HeadModel& head, const std::vector<double>& values,
                                bool degrees) {
  if (static_cast<int>(values.size()) != head.num_joints()) {
    throw InvalidArgument(fmt::format("--joints: {} values for the {} joints of head '{}' ({})",
                                      values.size(), head.num_joints(), head.name(),
                                      head::ListNames(*head.joint_names())));
  }
  head::JointState q(head.joint_names());
  for (int i = 0; i < head.num_joints(); ++i) {
    const bool prismatic =
        head.tree().joint(head.tree().variable_joint(i)).type == head::JointType::kPrismatic;
    q[i] = values[i] * (degrees && !prismatic ? kDegToRad : 1.0);
  }
  return q;
}

void AddDdsOptions(CLI::App* command, DdsOverrides& o) {
  command->add_option("--dds-domain", o.domain,
                      "DDS domain id, 0..232 (ROS_DOMAIN_ID; default the file's "
                      "transport.domain, else 0)");
  command->add_option("--dds-namespace", o.ns,
                      "ROS namespace of the relative topic names (e.g. /saccade)");
  command->add_option("--dds-config", o.config,
                      "Cyclone DDS configuration: loopback (default: nothing leaves the machine), "
                      "network (with --dds-interface), env (CYCLONEDDS_URI) or a file.xml");
  command->add_option("--dds-interface", o.interface,
                      "Network interface for DDS (e.g. eth0); implies --dds-config network");
  command->add_option("--dds-peer", o.peers,
                      "Unicast discovery peer (host or address) for networks without multicast; "
                      "repeatable");
  command->add_flag("--wall-stamps", o.wall_stamps,
                    "Stamp messages (and /clock) with the wall clock at the start plus the "
                    "simulated time, for ROS 2 tools without use_sim_time (default: simulated "
                    "seconds from 0; transport.stamps: wall)");
}

nlohmann::json DdsTransport(const DdsOverrides& o) {
  nlohmann::json transport = nlohmann::json::object();
  if (o.domain) transport["domain"] = *o.domain;
  if (!o.ns.empty()) transport["namespace"] = o.ns;
  if (!o.config.empty()) transport["config"] = o.config;
  if (!o.interface.empty()) {
    transport["interface"] = o.interface;
    if (o.config.empty()) transport["config"] = "network";
  }
  if (!o.peers.empty()) transport["peers"] = o.peers;
  if (o.wall_stamps) transport["stamps"] = "wall";
  return transport;
}

void ApplyDdsOverrides(const DdsOverrides& o, runtime::PipelineSpec& spec) {
  spec.transport.update(DdsTransport(o));
}

}  // namespace saccade::app
