#pragma once
// DDS as the pipelines' topic transport (runtime/pipeline.h: a connection may name a topic
// instead of a component's port). RegisterDdsTransport makes ComponentRegistry build topic
// connections over DDS; the pipeline file's `transport:` map chooses the domain and names:
//
//   transport:
//     domain: 0              # DDS domain id (ROS_DOMAIN_ID), 0..232
//     namespace: /saccade    # relative topic names go under it (ROS 2's rules)
//     config: loopback       # loopback (default) | network | env | PATH.xml (participant.h)
//     interface: eth0        # network: the interface
//     peers: [robot.local]   # network: unicast discovery peers
//     multicast: true        # network: multicast discovery
//     stamps: sim            # sim: stamps are simulated seconds from 0 (use_sim_time); wall:
//                            # the wall clock at the start plus those (stamps in the present)
//     clock: /clock          # where a pipeline that times its own steps (no clock.source)
//                            # publishes its clock each step, before its components
//                            # (rosgraph_msgs/Clock, as Gazebo); "" none
//
// A topic connection's own keys:
//   inputs:  {port: {topic: NAME, qos: PROFILE-OR-MAP, wait_s: S, start_wait_s: S, delay: 1}}
//            wait_s: each step waits at most S for a new message while a writer is matched
//            (simulated time steps on the sender's messages; 0: take what is there);
//            start_wait_s: the reader's first step waits at most S for a writer to appear
//            (in lockstep, for a writer in lockstep), where the message is needed: the
//            components before it in the step have published already
//   outputs: {port: NAME} or {port: {topic: NAME, qos: ..., start_wait_s: S, tf: /tf,
//             compressed: jpeg | png | "", jpeg_quality: Q}}
//            start_wait_s: after the step that wrote its first message (written at once, as
//            every other topic's), the pipeline waits at most S from that message for a
//            reader to match; every writer's wait runs against its own deadline, so they
//            overlap rather than add up
//            compressed: images also go out as sensor_msgs/CompressedImage on
//            <topic>/compressed (default jpeg, quality 90), encoded only while read
// QoS defaults: images "images", head.joints "latched" (a late-joining reader gets the newest
// state), the rest "default" (qos.h).
//
// Each reader reports at Stop what crossed: messages, lost, late, restarts (LinkStats).
#include <nlohmann/json.hpp>
#include <string>

#include "saccade/dds/participant.h"
#include "saccade/dds/qos.h"
#include "saccade/runtime/component_registry.h"

namespace saccade::dds {

/// What the `transport:` map says besides the domain.
struct TransportNames {
  std::string ns;                      ///< namespace of relative topic names ("" none)
  bool wall_stamps = false;            ///< `stamps: wall`
  std::string clock_topic = "/clock";  ///< `clock:`, resolved; "" publishes no clock
};

/// The pipeline's `transport:` map as domain options, a namespace and the rest. Throws
/// InvalidArgument naming the key, the value got and the values expected.
DomainOptions ParseTransport(const nlohmann::json& transport, std::string* ns = nullptr,
                             TransportNames* names = nullptr);

/// The offset `stamps: wall` adds to every stamp (TopicOptions::stamp_offset_ns): the wall
/// clock's time (ns since the Unix epoch) when the process first asked, the same for every
/// pipeline of the process.
int64_t WallStampOffsetNs();

/// The QoS a message type gets when its connection names none.
Qos DefaultQos(const std::string& message_type);

/// Makes `registry` build topic connections over DDS (idempotent).
void RegisterDdsTransport(runtime::ComponentRegistry& registry);

}  // namespace saccade::dds
