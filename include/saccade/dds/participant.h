#pragma once
// A DDS domain participant on Cyclone DDS, set up as ROS 2's rmw_cyclonedds sets up its own:
// USER_DATA "enclave=/;" so that `ros2 topic list` and `ros2 node list` on another machine
// see saccade's topics, and one of saccade's Cyclone configurations (config/dds/):
//
//   loopback   (the default) the loopback interface only: nothing leaves the machine; unicast
//              discovery on 127.0.0.1; 60 KB fragments; an 8 MiB receive buffer for images
//   network    the interface named by DomainOptions::interface, multicast discovery where
//              the network has it and unicast to DomainOptions::peers
//   env        whatever CYCLONEDDS_URI says (Cyclone's own default when unset)
//   PATH.xml   a Cyclone configuration file of the user's
//
// When the kernel's net.core.rmem_max is below the receive buffer the configuration asks
// for, Create logs a warning that names the value and the sysctl that raises it (Cyclone
// silently takes less, and images then lose fragments).
//
// Thread-safety: a Participant may be shared by the writers and readers of several threads.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace saccade::dds {

/// Highest DDS domain id (ROS_DOMAIN_ID's range on Linux is 0..101; DDS allows up to 232).
inline constexpr int kMaxDomainId = 232;

/// Which domain, and which Cyclone configuration.
struct DomainOptions {
  int domain_id = 0;                ///< 0..kMaxDomainId (ROS_DOMAIN_ID)
  std::string config = "loopback";  ///< loopback | network | env | a path to an .xml file
  std::string interface;            ///< network: the interface's name ("eth0") or address
  std::vector<std::string> peers;   ///< network: unicast discovery peers (host names, addresses)
  bool multicast = true;            ///< network: multicast discovery

  /// False (and `*error` says why) for a domain id out of range, an unknown config, or
  /// network without an interface.
  bool IsValid(std::string* error = nullptr) const;
};

/// The Cyclone XML configuration `options` selects ("" for env). Throws InvalidArgument when
/// the options are not valid or a config file cannot be read.
std::string CycloneConfigXml(const DomainOptions& options);

/// Receive buffer (bytes) saccade's configurations ask Cyclone for (images).
inline constexpr int64_t kReceiveBufferBytes = 8 * 1024 * 1024;

/// The kernel's net.core.rmem_max in bytes; -1 when it cannot be read.
int64_t KernelReceiveBufferMax();

/// One DDS domain participant. Create it with Participant::Create; writers and readers
/// (topics.h) hold it shared.
class Participant {
 public:
  /// Creates the participant in `options.domain_id` with its configuration. A domain that
  /// this process already created keeps its first configuration (Cyclone has one per domain
  /// and process). Throws InvalidArgument for bad options, saccade::Error when Cyclone fails
  /// (its message included).
  static std::shared_ptr<Participant> Create(const DomainOptions& options = {});
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  int domain_id() const { return domain_id_; }
  /// Cyclone's entity handle (dds_entity_t), for the module's own files.
  int32_t handle() const { return handle_; }

 private:
  Participant(int domain_id, int32_t handle) : domain_id_(domain_id), handle_(handle) {}
  int domain_id_;
  int32_t handle_;
};

}  // namespace saccade::dds
