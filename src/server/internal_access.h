#pragma once
// Who may talk to the GUI server (gui_server.h, "Security"): the Host a request names and the
// Origin of the page that sent it. Pure functions of the headers, tested on their own.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace saccade::server::internal {

/// What the server accepts in a Host header besides loopback names and addresses.
struct HostPolicy {
  std::string listen_address;              ///< ServerOptions::address
  std::vector<std::string> allowed_hosts;  ///< ServerOptions::allowed_hosts (names, no port)
  uint16_t port = 0;                       ///< the bound port: the only one a Host may name
};

/// A Host header value taken apart (RFC 9110 7.2: `host [":" port]`).
struct HostHeader {
  std::string host;  ///< lower case, without brackets: "example.com", "127.0.0.1", "::1"
  std::string port;  ///< the digits after the ':', exactly as sent; "" when none was
  bool has_port = false;
};

/// Parses a Host header value: a name (letters, digits, '.', '-', '_'), an IPv4 address, or an
/// IPv6 address in brackets ("[::1]"), then optionally ':' and 1 to 5 digits. Anything else
/// (userinfo "a@b", a path, an empty or non-numeric port "x:" "x:80x", an unbracketed or
/// invalid IPv6 address, a second ':') is malformed: nullopt.
std::optional<HostHeader> ParseHostHeader(std::string_view host_header);

/// The host part of a Host header value ("Example.com:8080" -> "example.com", "[::1]:80" ->
/// "::1"): lower case, without port or brackets; "" when malformed (ParseHostHeader).
std::string HostName(std::string_view host_header);

/// Whether a request naming `host_header` is for this server: exactly `host[:port]`
/// (ParseHostHeader), the port, when given, the server's own (`policy.port`, in its canonical
/// decimal form), and the host a loopback name or address (localhost, 127.0.0.0/8, ::1), the
/// listen address, any IP address when listening on all interfaces (0.0.0.0 or ::), or a name
/// of `allowed_hosts`. A name that is none of these is what a DNS-rebinding page sends. On
/// false, `why` says what was wrong.
bool HostAllowed(std::string_view host_header, const HostPolicy& policy, std::string* why);

/// Whether a request's Origin header (`origin`, "" when absent) is the server's own page:
/// the same scheme, host and port as the Host it was sent to. Browsers send an Origin on every
/// WebSocket and on cross-origin requests, so a foreign page is refused; programs that send
/// none (scripts) are allowed here and checked by the token. On false, `why` says why.
bool OriginAllowed(std::string_view origin, bool origin_present, std::string_view host_header,
                   std::string* why);

/// 128 random bits from the kernel (getrandom), as 32 lower-case hex digits.
std::string RandomToken();

}  // namespace saccade::server::internal
