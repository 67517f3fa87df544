#include "saccade/dds/participant.h"

#include <fmt/format.h>

#include <atomic>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>

#include "dds/internal_configs.h"
#include "dds/internal_cyclone.h"
#include "saccade/core/error.h"
#include "saccade/core/log.h"

namespace saccade::dds {
namespace {

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
    text.replace(at, from.size(), to);
    at += to.size();
  }
  return text;
}

bool SafeXmlValue(const std::string& value) {
  return value.find_first_of("<>&\"'") == std::string::npos;
}

// Warns once per process when the kernel caps the receive buffer the configuration asks for.
void WarnAboutReceiveBuffer() {
  static std::once_flag once;
  std::call_once(once, [] {
    const int64_t max = KernelReceiveBufferMax();
    if (max >= 0 && max < kReceiveBufferBytes) {
      log::Log(log::Level::kWarn,
               "dds: the kernel caps socket receive buffers at net.core.rmem_max = {} bytes, "
               "below the {} saccade's DDS configuration asks for images: a burst of image "
               "fragments may overflow it (reliable topics resend, best-effort ones lose the "
               "image). Raise it with: sudo sysctl -w net.core.rmem_max={}",
               max, kReceiveBufferBytes, kReceiveBufferBytes);
    }
  });
}

}  // namespace

bool DomainOptions::IsValid(std::string* error) const {
  const auto Fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (domain_id < 0 || domain_id > kMaxDomainId) {
    return Fail(fmt::format("domain id must be 0..{}, got {}", kMaxDomainId, domain_id));
  }
  if (config.empty())
    return Fail("config must be loopback, network, env or a path to an .xml file");
  if (config == "network") {
    if (interface.empty()) {
      return Fail("the network config needs an interface (--dds-interface NAME, e.g. eth0)");
    }
    if (!SafeXmlValue(interface)) return Fail("interface '" + interface + "' has XML characters");
    for (const std::string& peer : peers) {
      if (peer.empty() || !SafeXmlValue(peer)) return Fail("bad peer '" + peer + "'");
    }
  } else if (config != "loopback" && config != "env" &&
             !(config.size() > 4 && config.substr(config.size() - 4) == ".xml")) {
    return Fail("config must be loopback, network, env or a path to an .xml file, got '" + config +
                "'");
  }
  return true;
}

std::string CycloneConfigXml(const DomainOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw InvalidArgument("dds: " + error);
  if (options.config == "loopback") return internal::kLoopbackXml;
  if (options.config == "env") return "";
  if (options.config == "network") {
    std::string peers;
    for (const std::string& peer : options.peers) peers += "<Peer address=\"" + peer + "\"/>";
    std::string xml = Replace(internal::kNetworkXml, "@INTERFACE@", options.interface);
    xml = Replace(xml, "@MULTICAST@", options.multicast ? "true" : "false");
    return Replace(xml, "@PEERS@", peers);
  }
  std::ifstream in(options.config);
  if (!in) throw InvalidArgument("dds: cannot read the Cyclone configuration " + options.config);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

int64_t KernelReceiveBufferMax() {
  std::ifstream in("/proc/sys/net/core/rmem_max");
  int64_t value = -1;
  if (!(in >> value)) return -1;
  return value;
}

std::shared_ptr<Participant> Participant::Create(const DomainOptions& options) {
  const std::string xml = CycloneConfigXml(options);
  {
    // Cyclone keeps one configuration per domain and process: the first participant's.
    static std::mutex mutex;
    static std::set<int> created;
    std::lock_guard lock(mutex);
    if (!xml.empty() && !created.contains(options.domain_id)) {
      const dds_entity_t domain =
          dds_create_domain(static_cast<dds_domainid_t>(options.domain_id), xml.c_str());
      if (domain < 0 && domain != DDS_RETCODE_PRECONDITION_NOT_MET) {
        throw Error(fmt::format("dds: Cyclone refused the {} configuration for domain {}: {}",
                                options.config, options.domain_id, dds_strretcode(domain)));
      }
      created.insert(options.domain_id);
    }
  }
  WarnAboutReceiveBuffer();
  dds_qos_t* qos = dds_create_qos();
  // rmw_cyclonedds's participant user data: ROS 2 tools list the participant's topics.
  static constexpr char kUserData[] = "enclave=/;";
  dds_qset_userdata(qos, kUserData, sizeof(kUserData) - 1);
  const dds_entity_t participant =
      dds_create_participant(static_cast<dds_domainid_t>(options.domain_id), qos, nullptr);
  dds_delete_qos(qos);
  internal::Check(participant,
                  fmt::format("dds: cannot create a participant in domain {}", options.domain_id));
  return std::shared_ptr<Participant>(new Participant(options.domain_id, participant));
}

Participant::~Participant() { dds_delete(handle_); }

}  // namespace saccade::dds
