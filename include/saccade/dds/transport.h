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
//
// A topic connection's own keys:
//   inputs:  {port: {topic: NAME, qos: PROFILE-OR-MAP, wait_s: S, start_wait_s: S, delay: 1}}
//            wait_s: each step waits at most S for a new message while a writer is matched
//            (simulated time steps on the sender's messages; 0: take what is there);
//            start_wait_s: Start waits at most S for a writer to appear
//   outputs: {port: NAME} or {port: {topic: NAME, qos: ..., start_wait_s: S, tf: /tf}}
//            start_wait_s: the first message waits at most S for a reader to match
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

/// The pipeline's `transport:` map as domain options and a namespace. Throws InvalidArgument
/// naming the key, the value got and the values expected.
DomainOptions ParseTransport(const nlohmann::json& transport, std::string* ns = nullptr);

/// The QoS a message type gets when its connection names none.
Qos DefaultQos(const std::string& message_type);

/// Makes `registry` build topic connections over DDS (idempotent).
void RegisterDdsTransport(runtime::ComponentRegistry& registry);

}  // namespace saccade::dds
