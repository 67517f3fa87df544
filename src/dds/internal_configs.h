#pragma once
// The Cyclone DDS configurations shipped in config/dds/, compiled in (CMake embeds the files'
// text: internal_configs.cc.in), so that the program needs no file at run time.

namespace saccade::dds::internal {

/// config/dds/loopback.xml
extern const char* const kLoopbackXml;
/// config/dds/network.xml, with @INTERFACE@, @MULTICAST@ and @PEERS@ to fill in.
extern const char* const kNetworkXml;

}  // namespace saccade::dds::internal
