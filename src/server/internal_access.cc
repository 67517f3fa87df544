#include "server/internal_access.h"

#include <sys/random.h>

#include <algorithm>
#include <array>
#include <boost/asio/ip/address.hpp>
#include <cctype>
#include <cerrno>
#include <cstring>

#include "saccade/core/error.h"
#include "saccade/server/gui_server.h"

namespace saccade::server::internal {
namespace {

std::string Lower(std::string_view in) {
  std::string out(in);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

bool IsIpAddress(const std::string& host) {
  boost::system::error_code ec;
  boost::asio::ip::make_address(host, ec);
  return !ec;
}

bool IsUnspecified(const std::string& address) {
  boost::system::error_code ec;
  const auto parsed = boost::asio::ip::make_address(address, ec);
  return !ec && parsed.is_unspecified();
}

}  // namespace

std::optional<HostHeader> ParseHostHeader(std::string_view host_header) {
  HostHeader out;
  std::string_view host;
  std::string_view rest;
  if (!host_header.empty() && host_header.front() == '[') {
    const std::size_t close = host_header.find(']');
    if (close == std::string_view::npos) return std::nullopt;
    host = host_header.substr(1, close - 1);
    rest = host_header.substr(close + 1);
    // Only an IPv6 address goes in brackets (no zone id: '%' is not allowed in a Host).
    boost::system::error_code ec;
    boost::asio::ip::make_address_v6(std::string(host), ec);
    if (ec || host.find('%') != std::string_view::npos) return std::nullopt;
  } else {
    const std::size_t colon = host_header.find(':');
    host = host_header.substr(0, colon);
    rest = colon == std::string_view::npos ? std::string_view() : host_header.substr(colon);
    if (host.empty()) return std::nullopt;
    for (const char c : host) {
      const auto u = static_cast<unsigned char>(c);
      if (!(std::isalnum(u) || c == '.' || c == '-' || c == '_')) return std::nullopt;
    }
  }
  if (!rest.empty()) {
    // ':' then the port's digits and nothing else: no userinfo, path or second colon.
    const std::string_view port = rest.substr(1);
    if (rest.front() != ':' || port.empty() || port.size() > 5) return std::nullopt;
    for (const char c : port) {
      if (c < '0' || c > '9') return std::nullopt;
    }
    out.port = std::string(port);
    out.has_port = true;
  }
  out.host = Lower(host);
  return out;
}

std::string HostName(std::string_view host_header) {
  const std::optional<HostHeader> parsed = ParseHostHeader(host_header);
  return parsed ? parsed->host : "";
}

bool HostAllowed(std::string_view host_header, const HostPolicy& policy, std::string* why) {
  if (host_header.empty()) {
    *why = "the request names no Host";
    return false;
  }
  const std::optional<HostHeader> parsed = ParseHostHeader(host_header);
  if (!parsed) {
    *why = "the Host '" + std::string(host_header) +
           "' is malformed (expected host[:port], e.g. 127.0.0.1:" + std::to_string(policy.port) +
           ", [::1]:" + std::to_string(policy.port) + " or localhost)";
    return false;
  }
  if (parsed->has_port && parsed->port != std::to_string(policy.port)) {
    *why = "the Host '" + std::string(host_header) + "' names port " + parsed->port +
           ", not this server's port " + std::to_string(policy.port);
    return false;
  }
  const std::string& host = parsed->host;
  if (IsLoopbackAddress(host)) return true;
  if (host == Lower(policy.listen_address)) return true;
  if (IsUnspecified(policy.listen_address) && IsIpAddress(host)) return true;
  for (const std::string& allowed : policy.allowed_hosts) {
    if (host == Lower(allowed)) return true;
  }
  *why = "the Host '" + std::string(host_header) +
         "' is not this server (allowed: localhost, loopback addresses, " +
         (IsUnspecified(policy.listen_address) ? std::string("any IP address")
                                               : "the listen address " + policy.listen_address) +
         (policy.allowed_hosts.empty() ? std::string() : ", the --allow-host names") +
         "); a DNS-rebinding page sends a name of its own";
  return false;
}

bool OriginAllowed(std::string_view origin, bool origin_present, std::string_view host_header,
                   std::string* why) {
  if (!origin_present) return true;
  const std::string expected = "http://" + Lower(host_header);
  if (Lower(origin) == expected) return true;
  *why = "the Origin '" + std::string(origin) + "' is not this server's page (" + expected +
         "); another web page cannot drive the head";
  return false;
}

std::string RandomToken() {
  std::array<unsigned char, 16> bytes{};
  std::size_t got = 0;
  while (got < bytes.size()) {
    const ssize_t n = getrandom(bytes.data() + got, bytes.size() - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw Error(std::string("GuiServer: no random bytes for the access token: ") +
                  std::strerror(errno));
    }
    got += static_cast<std::size_t>(n);
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string token;
  for (const unsigned char b : bytes) {
    token.push_back(kHex[b >> 4]);
    token.push_back(kHex[b & 15]);
  }
  return token;
}

}  // namespace saccade::server::internal
