// The browser GUI's server: Boost.Beast HTTP + WebSocket on one I/O thread (gui_server.h,
// docs/gui-protocol.md).
//
// Threads: everything that touches a socket runs on the I/O thread. Publish*, Broadcast and
// the accessors run on any thread: they take a session's mutex briefly to replace its pending
// state or frame (or queue a text), then post a "kick" to the I/O thread when the session is
// idle. Each session has at most one write in flight and picks the next message when it
// completes: queued texts, then the state, then the frames round-robin over cameras.
//
// Lock order: clients_mutex (Impl) before a session's mutex; never the other way round.

#include "saccade/server/gui_server.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <string_view>
#include <thread>
#include <utility>

#include "saccade/core/log.h"
#include "server/internal_access.h"
#include "server/internal_http_session.h"
#include "server/internal_server_core.h"
#include "server/internal_ws_session.h"

namespace saccade::server {

using namespace internal_gui;  // NOLINT: the server's own private parts

struct GuiServer::Impl {
  explicit Impl(ServerOptions options) : core(std::move(options)) {}
  internal_gui::ServerCore core;
};

GuiServer::GuiServer(ServerOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  const ServerOptions& o = impl_->core.options;
  beast::error_code ec;
  if (o.address != "localhost") {
    asio::ip::make_address(o.address, ec);
    if (ec) {
      throw InvalidArgument("GuiServer: address '" + o.address +
                            "' is not an IPv4 or IPv6 address (expected e.g. 127.0.0.1 or ::1)");
    }
  }
  if (!IsLoopbackAddress(o.address) && o.token.empty()) {
    throw InvalidArgument("GuiServer: listening on " + o.address +
                          ", not a loopback address, requires an access token (--token TOKEN "
                          "or SACCADE_GUI_TOKEN)");
  }
  for (const std::string& host : o.allowed_hosts) {
    if (host.empty() || internal::HostName(host) != host) {
      throw InvalidArgument("GuiServer: allowed host '" + host +
                            "' is not a host name (expected e.g. robot-head.local, without "
                            "scheme, port or path, in lower case)");
    }
  }
  if (o.max_message_bytes == 0 || o.max_clients < 1 || o.max_queued_messages == 0 ||
      o.max_http_sessions < 1 || o.http_timeout.count() <= 0) {
    throw InvalidArgument(
        "GuiServer: max_message_bytes, max_clients, max_queued_messages, max_http_sessions and "
        "http_timeout must be positive, got " +
        std::to_string(o.max_message_bytes) + ", " + std::to_string(o.max_clients) + ", " +
        std::to_string(o.max_queued_messages) + ", " + std::to_string(o.max_http_sessions) + ", " +
        std::to_string(o.http_timeout.count()) + " ms");
  }
  for (const auto& [prefix, folder] : o.mounts) {
    if (prefix.empty() || prefix.front() != '/' || prefix.back() != '/') {
      throw InvalidArgument("GuiServer: mount prefix '" + prefix +
                            "' must start and end with '/' (e.g. \"/vendor/three/\")");
    }
    std::error_code fec;
    if (!fs::is_directory(folder, fec)) {
      throw InvalidArgument("GuiServer: mount " + prefix + ": folder '" + folder +
                            "' does not exist or is not a folder");
    }
    impl_->core.mounts.emplace_back(prefix, fs::canonical(folder));
  }
}

GuiServer::~GuiServer() { Stop(); }

void GuiServer::SetCommandHandler(CommandHandler handler) {
  std::lock_guard lock(impl_->core.config_mutex);
  impl_->core.handler = std::move(handler);
}

void GuiServer::SetDocument(const std::string& path, const std::string& content_type,
                            std::string body) {
  auto document = std::make_shared<const Document>(Document{content_type, std::move(body)});
  std::lock_guard lock(impl_->core.config_mutex);
  impl_->core.documents[path] = std::move(document);
}

void GuiServer::SetWelcome(std::function<std::vector<std::string>()> welcome) {
  std::lock_guard lock(impl_->core.config_mutex);
  impl_->core.welcome = std::move(welcome);
}

void GuiServer::Start() {
  internal_gui::ServerCore& impl = impl_->core;
  if (impl.thread.joinable() || impl.stopping) {
    throw Error("GuiServer::Start: the server was already started (a server starts once)");
  }
  const ServerOptions& o = impl.options;
  const std::string where = o.address + " port " + std::to_string(o.port);
  try {
    const auto address = o.address == "localhost" ? asio::ip::make_address("127.0.0.1")
                                                  : asio::ip::make_address(o.address);
    const tcp::endpoint endpoint(address, o.port);
    impl.acceptor.emplace(impl.ioc);
    impl.acceptor->open(endpoint.protocol());
    impl.acceptor->set_option(asio::socket_base::reuse_address(true));
    impl.acceptor->bind(endpoint);
    impl.acceptor->listen(asio::socket_base::max_listen_connections);
    impl.bound_port = impl.acceptor->local_endpoint().port();
    impl.host_policy.port = impl.bound_port;  // before the I/O thread reads it
  } catch (const boost::system::system_error& e) {
    impl.acceptor.reset();
    throw Error("GuiServer::Start: cannot listen on " + where + ": " + e.code().message());
  }
  impl.DoAccept();
  impl.thread = std::thread([&impl] {
    for (;;) {
      try {
        impl.ioc.run();
        return;
      } catch (const std::exception& e) {
        // A bug in a handler; the server goes on serving the others.
        log::Error("GUI server: {}", e.what());
      }
    }
  });
}

void GuiServer::Stop() {
  internal_gui::ServerCore& impl = impl_->core;
  if (!impl.thread.joinable()) return;
  SACCADE_ASSERT(impl.thread.get_id() != std::this_thread::get_id(),
                 "GuiServer::Stop called on the server's I/O thread (from a command handler?)");
  asio::post(impl.ioc, [&impl] { impl.CloseAll(); });
  impl.thread.join();
  std::lock_guard lock(impl.clients_mutex);
  impl.clients.clear();
}

uint16_t GuiServer::port() const { return impl_->core.bound_port; }

std::string GuiServer::url() const {
  const std::string& address = impl_->core.options.address;
  const bool v6 = address.find(':') != std::string::npos;
  std::string url =
      "http://" + (v6 ? "[" + address + "]" : address) + ":" + std::to_string(port()) + "/";
  if (!impl_->core.options.token.empty())
    url += "?token=" + PercentEncode(impl_->core.options.token);
  return url;
}

void GuiServer::PublishState(const nlohmann::json& state) {
  const auto text = std::make_shared<const std::string>(
      state.dump(-1, ' ', false, json::error_handler_t::replace));
  {
    std::lock_guard lock(impl_->core.config_mutex);
    impl_->core.latest_state = text;
  }
  for (const auto& session : impl_->core.Snapshot()) session->OfferState(text);
}

void GuiServer::PublishLatest(const std::string& kind, const nlohmann::json& message) {
  const auto text = std::make_shared<const std::string>(
      message.dump(-1, ' ', false, json::error_handler_t::replace));
  {
    std::lock_guard lock(impl_->core.config_mutex);
    impl_->core.latest_of_kind[kind] = text;
  }
  for (const auto& session : impl_->core.Snapshot()) session->OfferLatest(kind, text);
}

void GuiServer::PublishFrame(const std::string& camera, const nlohmann::json& header,
                             std::shared_ptr<const std::string> payload) {
  const std::string header_text = header.dump(-1, ' ', false, json::error_handler_t::replace);
  const auto length = static_cast<uint32_t>(header_text.size());
  std::string head;
  head.reserve(4 + header_text.size());
  for (int shift = 0; shift < 32; shift += 8) {
    head.push_back(static_cast<char>((length >> shift) & 0xff));
  }
  head += header_text;
  const Frame frame{std::make_shared<const std::string>(std::move(head)), std::move(payload)};
  for (const auto& session : impl_->core.Snapshot()) session->OfferFrame(camera, frame);
}

void GuiServer::Broadcast(const nlohmann::json& event) {
  const auto text = std::make_shared<const std::string>(
      event.dump(-1, ' ', false, json::error_handler_t::replace));
  for (const auto& session : impl_->core.Snapshot()) session->OfferText(text);
}

int GuiServer::client_count() const {
  std::lock_guard lock(impl_->core.clients_mutex);
  return static_cast<int>(impl_->core.clients.size());
}

std::vector<ClientStats> GuiServer::clients() const {
  std::vector<ClientStats> out;
  for (const auto& session : impl_->core.Snapshot()) out.push_back(session->stats());
  return out;
}

std::string GenerateToken() { return internal::RandomToken(); }

bool IsLoopbackAddress(const std::string& address) {
  if (address == "localhost") return true;
  beast::error_code ec;
  const auto parsed = asio::ip::make_address(address, ec);
  if (ec) return false;
  if (parsed.is_v4()) return parsed.to_v4().is_loopback();
  const auto v6 = parsed.to_v6();
  if (v6.is_v4_mapped()) {
    return asio::ip::make_address_v4(asio::ip::v4_mapped, v6).is_loopback();
  }
  return v6.is_loopback();
}

}  // namespace saccade::server
