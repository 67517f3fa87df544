#pragma once
// The GUI server's shared state and the helpers its sessions use (private to the server
// module): URL and percent coding, content types, the folder check of static files, the
// messages waiting for clients, and ServerCore, which the HTTP and WebSocket sessions share.
// gui_server.cc explains the threads and the lock order.
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
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "saccade/server/gui_server.h"
#include "server/internal_access.h"
#include "server/internal_command.h"

namespace saccade::server::internal_gui {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace fs = std::filesystem;
using tcp = asio::ip::tcp;
using nlohmann::json;

inline constexpr std::size_t kHttpBodyLimit = 64 * 1024;  // GET/HEAD carry no body worth more
// The hard bound on one incoming WebSocket message, as a multiple of max_message_bytes:
// messages up to it are read whole and answered with an error; beyond it Beast closes the
// connection with 1009 (message too big).
inline constexpr std::size_t kHardMessageFactor = 16;
inline constexpr const char* kServerName = "saccade";
// The largest `frame_window` a client may ask for (frames sent and not acknowledged).
inline constexpr int kMaxFrameWindow = 64;
// After a failed accept (out of file descriptors, most often) the next waits this long,
// doubling up to the cap; a success resets it. Retrying at once would spin: the connection
// stays in the backlog and the next accept fails the same way.
inline constexpr auto kAcceptBackoffMin = std::chrono::milliseconds(5);
inline constexpr auto kAcceptBackoffMax = std::chrono::milliseconds(200);
// Refused connections and failed accepts are logged at most this often, with a count.
inline constexpr auto kFloodLogInterval = std::chrono::seconds(10);

// Beast 1.74 speaks boost::string_view.
inline std::string_view View(beast::string_view v) { return {v.data(), v.size()}; }

inline int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Percent-decodes `in`; false on a malformed escape.
inline bool PercentDecode(std::string_view in, std::string* out) {
  out->clear();
  out->reserve(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] != '%') {
      out->push_back(in[i]);
      continue;
    }
    if (i + 2 >= in.size()) return false;
    const int hi = HexValue(in[i + 1]);
    const int lo = HexValue(in[i + 2]);
    if (hi < 0 || lo < 0) return false;
    out->push_back(static_cast<char>(hi * 16 + lo));
    i += 2;
  }
  return true;
}

inline std::string PercentEncode(std::string_view in) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out;
  for (const char c : in) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u) || c == '-' || c == '_' || c == '.' || c == '~') {
      out.push_back(c);
    } else {
      out.push_back('%');
      out.push_back(kHex[u >> 4]);
      out.push_back(kHex[u & 15]);
    }
  }
  return out;
}

// The value of `key` in a query string ("a=1&token=x"), decoded; nullopt when absent.
inline std::optional<std::string> QueryValue(std::string_view query, std::string_view key) {
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    query = amp == std::string_view::npos ? std::string_view() : query.substr(amp + 1);
    const std::size_t eq = pair.find('=');
    if (pair.substr(0, eq) != key) continue;
    std::string value;
    if (eq == std::string_view::npos) return value;
    if (!PercentDecode(pair.substr(eq + 1), &value)) return std::nullopt;
    return value;
  }
  return std::nullopt;
}

// Compares without returning early, so the time taken says nothing about the token.
inline bool SameSecret(std::string_view a, std::string_view b) {
  unsigned diff = a.size() == b.size() ? 0u : 1u;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff |= static_cast<unsigned>(a[i] ^ (i < b.size() ? b[i] : 0));
  }
  return diff == 0;
}

inline std::string ContentType(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static const std::map<std::string, std::string, std::less<>> kTypes = {
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".jpeg", "image/jpeg"},
      {".json", "application/json"},
      {".svg", "image/svg+xml"},
      {".wasm", "application/wasm"},
      {".map", "application/json"},
      {".bin", "application/octet-stream"},
      {".txt", "text/plain; charset=utf-8"},
  };
  const auto it = kTypes.find(ext);
  return it == kTypes.end() ? "application/octet-stream" : it->second;
}

// True when `path` is `root` or inside it (both canonical).
inline bool IsInside(const fs::path& path, const fs::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // a trailing separator
    if (p == path.end() || *p != *r) return false;
  }
  return true;
}

inline std::string EndpointText(const tcp::endpoint& endpoint) {
  const auto address = endpoint.address();
  const std::string host = address.is_v6() ? "[" + address.to_string() + "]" : address.to_string();
  return host + ":" + std::to_string(endpoint.port());
}

inline json StatsJson(const ClientStats& s) {
  return json{{"id", s.id},
              {"peer", s.peer},
              {"states_sent", s.states_sent},
              {"states_skipped", s.states_skipped},
              {"frames_sent", s.frames_sent},
              {"frames_skipped", s.frames_skipped},
              {"messages_dropped", s.messages_dropped},
              {"commands", s.commands},
              {"errors", s.errors},
              {"queued_bytes", s.queued_bytes},
              {"frame_window", s.frame_window},
              {"frames_acked", s.frames_acked}};
}

struct Document {
  std::string content_type;
  std::string body;
};

// One frame as it waits for a client: the [length, header] prefix and the payload, both
// shared by every client.
struct Frame {
  std::shared_ptr<const std::string> head;
  std::shared_ptr<const std::string> payload;
  std::size_t bytes() const { return head->size() + (payload ? payload->size() : 0); }
};

using Text = std::shared_ptr<const std::string>;

class WsSession;
class HttpSession;

// The server's state, shared by the sessions (GuiServer::Impl is private to GuiServer).
struct ServerCore {
  explicit ServerCore(ServerOptions o)
      : options(std::move(o)), host_policy{options.address, options.allowed_hosts} {}

  // Declared first: destroyed last, after every socket that uses it.
  asio::io_context ioc{1};
  ServerOptions options;
  internal::HostPolicy host_policy;
  std::vector<std::pair<std::string, fs::path>> mounts;  // prefix -> canonical folder

  mutable std::mutex config_mutex;  // handler, documents, welcome, latest_state
  CommandHandler handler;
  std::map<std::string, std::shared_ptr<const Document>, std::less<>> documents;
  std::function<std::vector<std::string>()> welcome;
  Text latest_state;  // the newest published state, for clients that connect later
  std::map<std::string, Text> latest_of_kind;  // PublishLatest's, for clients that come later

  mutable std::mutex clients_mutex;
  std::map<int64_t, std::shared_ptr<WsSession>> clients;
  int64_t next_client_id = 1;

  // I/O thread only (and Start/Stop while the thread is not running).
  std::optional<tcp::acceptor> acceptor;
  std::vector<std::weak_ptr<HttpSession>> http_sessions;
  asio::steady_timer accept_timer{ioc};
  std::chrono::milliseconds accept_backoff{0};  // 0: the last accept succeeded
  int64_t accept_failures = 0;                  // since the last log line
  bool accept_warned = false;                   // a failure was logged, the recovery not yet
  int64_t refused_sessions = 0;                 // over max_http_sessions, since the last log line
  std::chrono::steady_clock::time_point accept_logged{};
  std::chrono::steady_clock::time_point refusal_logged{};
  std::atomic<bool> stopping{false};

  std::thread thread;
  std::atomic<uint16_t> bound_port{0};

  void DoAccept();
  // A failed accept: waits accept_backoff (growing) before the next, logs now and then.
  void OnAcceptError(beast::error_code ec);
  // A connection over max_http_sessions: a best-effort 503, then closed.
  void Refuse(tcp::socket socket);
  void CloseAll();
  void RemoveClient(int64_t id) {
    std::lock_guard lock(clients_mutex);
    clients.erase(id);
  }
  std::vector<std::shared_ptr<WsSession>> Snapshot() const {
    std::lock_guard lock(clients_mutex);
    std::vector<std::shared_ptr<WsSession>> out;
    out.reserve(clients.size());
    for (const auto& [id, session] : clients) out.push_back(session);
    return out;
  }
  bool TokenOk(const http::request<http::string_body>& req, std::string_view query) const;
};

}  // namespace saccade::server::internal_gui
