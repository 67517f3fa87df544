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

namespace saccade::server {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace fs = std::filesystem;
using tcp = asio::ip::tcp;
using nlohmann::json;

namespace {

constexpr auto kHttpTimeout = std::chrono::seconds(60);  // idle keep-alive and slow requests
constexpr std::size_t kHttpBodyLimit = 64 * 1024;        // GET/HEAD carry no body worth more
// The hard bound on one incoming WebSocket message, as a multiple of max_message_bytes:
// messages up to it are read whole and answered with an error; beyond it Beast closes the
// connection with 1009 (message too big).
constexpr std::size_t kHardMessageFactor = 16;
constexpr const char* kServerName = "saccade";

// Beast 1.74 speaks boost::string_view.
std::string_view View(beast::string_view v) { return {v.data(), v.size()}; }

int HexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Percent-decodes `in`; false on a malformed escape.
bool PercentDecode(std::string_view in, std::string* out) {
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

std::string PercentEncode(std::string_view in) {
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
std::optional<std::string> QueryValue(std::string_view query, std::string_view key) {
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
bool SameSecret(std::string_view a, std::string_view b) {
  unsigned diff = a.size() == b.size() ? 0u : 1u;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff |= static_cast<unsigned>(a[i] ^ (i < b.size() ? b[i] : 0));
  }
  return diff == 0;
}

std::string ContentType(const fs::path& path) {
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
bool IsInside(const fs::path& path, const fs::path& root) {
  auto p = path.begin();
  for (auto r = root.begin(); r != root.end(); ++r, ++p) {
    if (r->empty()) continue;  // a trailing separator
    if (p == path.end() || *p != *r) return false;
  }
  return true;
}

std::string EndpointText(const tcp::endpoint& endpoint) {
  const auto address = endpoint.address();
  const std::string host = address.is_v6() ? "[" + address.to_string() + "]" : address.to_string();
  return host + ":" + std::to_string(endpoint.port());
}

json StatsJson(const ClientStats& s) {
  return json{{"id", s.id},
              {"peer", s.peer},
              {"states_sent", s.states_sent},
              {"states_skipped", s.states_skipped},
              {"frames_sent", s.frames_sent},
              {"frames_skipped", s.frames_skipped},
              {"messages_dropped", s.messages_dropped},
              {"commands", s.commands},
              {"errors", s.errors},
              {"queued_bytes", s.queued_bytes}};
}

std::string JsonTypeName(const json& value) { return value.type_name(); }

// Commands nest a few levels; deeper input is refused before parsing, so that no handler
// walks (or dumps) it recursively.
constexpr int kMaxNesting = 64;

// The deepest nesting of arrays and objects in JSON text (strings skipped).
int NestingDepth(std::string_view text) {
  int depth = 0;
  int deepest = 0;
  bool in_string = false;
  bool escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
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

}  // namespace

namespace internal_gui {

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

  mutable std::mutex clients_mutex;
  std::map<int64_t, std::shared_ptr<WsSession>> clients;
  int64_t next_client_id = 1;

  // I/O thread only (and Start/Stop while the thread is not running).
  std::optional<tcp::acceptor> acceptor;
  std::vector<std::weak_ptr<HttpSession>> http_sessions;
  std::atomic<bool> stopping{false};

  std::thread thread;
  std::atomic<uint16_t> bound_port{0};

  void DoAccept();
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

// ---------------------------------------------------------------------------------------------
// WebSocket session
// ---------------------------------------------------------------------------------------------

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(ServerCore* server, tcp::socket socket, int64_t id)
      : server_(server), ws_(std::move(socket)) {
    stats_.id = id;
    boost::system::error_code ec;
    const auto endpoint = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
    if (!ec) stats_.peer = EndpointText(endpoint);
  }

  int64_t id() const { return stats_.id; }

  // I/O thread: completes the handshake with the upgrade request already read.
  void Run(http::request<http::string_body> req) {
    beast::get_lowest_layer(ws_).expires_after(kHttpTimeout);
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& res) { res.set(http::field::server, kServerName); }));
    ws_.read_message_max(server_->options.max_message_bytes * kHardMessageFactor);
    ws_.async_accept(req,
                     [self = shared_from_this()](beast::error_code ec) { self->OnAccept(ec); });
  }

  // Any thread: replaces the pending state.
  void OfferState(const Text& state) {
    bool kick = false;
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      if (state_) {
        ++stats_.states_skipped;
        queued_bytes_ -= state_->size();
      }
      state_ = state;
      queued_bytes_ += state->size();
      kick = NeedsKickLocked();
    }
    if (kick) PostKick();
  }

  // Any thread: replaces the pending frame of `camera`.
  void OfferFrame(const std::string& camera, const Frame& frame) {
    bool kick = false;
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      auto [it, inserted] = frames_.try_emplace(camera, frame);
      if (!inserted) {
        ++stats_.frames_skipped;
        queued_bytes_ -= it->second.bytes();
        it->second = frame;
      }
      queued_bytes_ += frame.bytes();
      kick = NeedsKickLocked();
    }
    if (kick) PostKick();
  }

  // Any thread: queues a text message, dropping the oldest when the queue is full.
  void OfferText(const Text& text) {
    bool kick = false;
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      QueueTextLocked(text);
      kick = NeedsKickLocked();
    }
    if (kick) PostKick();
  }

  ClientStats stats() const {
    std::lock_guard lock(mutex_);
    ClientStats s = stats_;
    s.queued_bytes = queued_bytes_;
    return s;
  }

  // I/O thread: closes the connection at once (pending writes are abandoned).
  void Close() {
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      closed_ = true;
      texts_.clear();
      state_.reset();
      frames_.clear();
      queued_bytes_ = in_flight_bytes_;
    }
    server_->RemoveClient(stats_.id);
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
    beast::get_lowest_layer(ws_).close();
  }

 private:
  void OnAccept(beast::error_code ec) {
    if (ec || server_->stopping) {
      Close();
      return;
    }
    // Beast's own WebSocket timeouts stay off: a slow reader must not be dropped, and Stop()
    // closes the sockets itself.
    beast::get_lowest_layer(ws_).expires_never();
    json hello = server_->options.hello.is_object() ? server_->options.hello : json::object();
    hello["type"] = "hello";
    hello["protocol"] = kProtocolName;
    hello["version"] = kProtocolVersion;
    hello["client"] = stats_.id;
    std::function<std::vector<std::string>()> welcome;
    Text latest_state;
    {
      std::lock_guard lock(server_->config_mutex);
      welcome = server_->welcome;
      latest_state = server_->latest_state;
    }
    std::vector<Text> texts{std::make_shared<const std::string>(
        hello.dump(-1, ' ', false, json::error_handler_t::replace))};
    if (welcome) {
      try {
        for (std::string& text : welcome()) {
          texts.push_back(std::make_shared<const std::string>(std::move(text)));
        }
      } catch (const std::exception& e) {
        const json event = {{"type", "event"},
                            {"level", "error"},
                            {"message", std::string("welcome: ") + e.what()}};
        texts.push_back(std::make_shared<const std::string>(event.dump()));
      }
    }
    {
      std::lock_guard lock(mutex_);
      // The hello goes before anything published during the handshake.
      for (auto it = texts.rbegin(); it != texts.rend(); ++it) {
        texts_.push_front(*it);
        queued_bytes_ += (*it)->size();
      }
      // Then the newest state, unless one published during the handshake is already here.
      if (!state_ && latest_state) {
        state_ = latest_state;
        queued_bytes_ += state_->size();
      }
      open_ = true;
    }
    MaybeWrite();
    DoRead();
  }

  void DoRead() {
    ws_.async_read(read_buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->OnRead(ec);
    });
  }

  void OnRead(beast::error_code ec) {
    if (ec) {
      Close();
      return;
    }
    const std::size_t size = read_buffer_.size();
    {
      std::lock_guard lock(mutex_);
      ++stats_.commands;
    }
    const std::size_t limit = server_->options.max_message_bytes;
    if (!ws_.got_text()) {
      SendError(nullptr, "binary messages are not commands");
    } else if (size > limit) {
      SendError(nullptr, "message of " + std::to_string(size) +
                             " bytes is larger than the limit of " + std::to_string(limit) +
                             " bytes");
    } else {
      const auto data = read_buffer_.data();
      HandleCommand(std::string_view(static_cast<const char*>(data.data()), data.size()));
    }
    read_buffer_.consume(size);
    if (read_buffer_.capacity() > 2 * limit) read_buffer_.shrink_to_fit();
    if (!IsClosed()) DoRead();
  }

  void HandleCommand(std::string_view text) {
    if (const int depth = NestingDepth(text); depth > kMaxNesting) {
      SendError(nullptr, "malformed JSON: nested " + std::to_string(depth) +
                             " levels deep, at most " + std::to_string(kMaxNesting));
      return;
    }
    json command;
    try {
      command = json::parse(text);
    } catch (const json::exception& e) {
      SendError(nullptr, std::string("malformed JSON: ") + e.what());
      return;
    }
    if (!command.is_object()) {
      SendError(nullptr, "a command must be a JSON object, got " + JsonTypeName(command));
      return;
    }
    // The id, when there is a valid one, goes into every error below.
    json id = nullptr;
    const auto id_it = command.find("id");
    const bool id_ok =
        id_it != command.end() && id_it->is_number_integer() &&
        !(id_it->is_number_unsigned() &&
          id_it->get<uint64_t>() > static_cast<uint64_t>(std::numeric_limits<int64_t>::max()));
    if (id_ok) id = id_it->get<int64_t>();
    const auto type_it = command.find("type");
    if (type_it == command.end()) {
      SendError(id, "missing field 'type' (a string naming the command)");
      return;
    }
    if (!type_it->is_string()) {
      SendError(id, "field 'type' must be a string, got " + JsonTypeName(*type_it));
      return;
    }
    if (id_it == command.end()) {
      SendError(nullptr, "missing field 'id' (an integer that grows with each command)");
      return;
    }
    if (!id_ok) {
      SendError(nullptr, "field 'id' must be an integer (int64), got " +
                             (id_it->is_number_integer() ? std::string("an out-of-range number")
                                                         : JsonTypeName(*id_it)));
      return;
    }
    const int64_t id_value = id.get<int64_t>();
    if (last_id_ && id_value <= *last_id_) {
      SendError(id, "out of order: id " + std::to_string(id_value) + " after " +
                        std::to_string(*last_id_));
      return;
    }
    last_id_ = id_value;

    CommandHandler handler;
    {
      std::lock_guard lock(server_->config_mutex);
      handler = server_->handler;
    }
    if (!handler) {
      SendError(id, "this server takes no commands (no command handler)");
      return;
    }
    json reply;
    try {
      json result = handler(command, stats_.id);
      if (result.is_object()) {
        reply = std::move(result);
      } else {
        reply = json::object();
        if (!result.is_null()) reply["result"] = std::move(result);
      }
    } catch (const std::exception& e) {
      SendError(id, e.what());
      return;
    } catch (...) {
      SendError(id, "command failed with an unknown exception");
      return;
    }
    reply["type"] = "reply";
    reply["id"] = id_value;
    reply["ok"] = true;
    QueueOwnText(reply);
  }

  void SendError(json id, const std::string& message) {
    {
      std::lock_guard lock(mutex_);
      ++stats_.errors;
    }
    QueueOwnText(json{{"type", "error"}, {"id", std::move(id)}, {"error", message}});
  }

  // I/O thread: queues a reply or error and starts a write when idle.
  void QueueOwnText(const json& message) {
    std::string text;
    try {
      text = message.dump(-1, ' ', false, json::error_handler_t::replace);
    } catch (const std::exception& e) {
      text = json{{"type", "error"}, {"id", nullptr}, {"error", e.what()}}.dump();
    }
    {
      std::lock_guard lock(mutex_);
      if (closed_) return;
      QueueTextLocked(std::make_shared<const std::string>(std::move(text)));
    }
    MaybeWrite();
  }

  bool IsClosed() const {
    std::lock_guard lock(mutex_);
    return closed_;
  }

  void QueueTextLocked(const Text& text) {
    while (!texts_.empty() && texts_.size() >= server_->options.max_queued_messages) {
      DropOldestLocked();
    }
    texts_.push_back(text);
    queued_bytes_ += text->size();
  }

  void DropOldestLocked() {
    queued_bytes_ -= texts_.front()->size();
    texts_.pop_front();
    ++stats_.messages_dropped;
  }

  bool NeedsKickLocked() {
    if (!open_ || closed_ || writing_ || kick_pending_) return false;
    kick_pending_ = true;
    return true;
  }

  void PostKick() {
    asio::post(ws_.get_executor(), [self = shared_from_this()] {
      {
        std::lock_guard lock(self->mutex_);
        self->kick_pending_ = false;
      }
      self->MaybeWrite();
    });
  }

  // I/O thread: starts the next write when none is in flight.
  void MaybeWrite() {
    enum class Kind { kText, kState, kFrame } kind;
    {
      std::lock_guard lock(mutex_);
      if (!open_ || closed_ || writing_) return;
      if (!texts_.empty()) {
        kind = Kind::kText;
        out_text_ = std::move(texts_.front());
        texts_.pop_front();
        in_flight_bytes_ = out_text_->size();
      } else if (state_) {
        kind = Kind::kState;
        out_text_ = std::move(state_);
        state_.reset();
        in_flight_bytes_ = out_text_->size();
      } else if (!frames_.empty()) {
        kind = Kind::kFrame;
        auto it = frames_.upper_bound(last_camera_);
        if (it == frames_.end()) it = frames_.begin();
        last_camera_ = it->first;
        out_frame_ = std::move(it->second);
        frames_.erase(it);
        in_flight_bytes_ = out_frame_.bytes();
      } else {
        return;
      }
      writing_ = true;
    }
    auto self = shared_from_this();
    if (kind == Kind::kFrame) {
      ws_.binary(true);
      std::array<asio::const_buffer, 2> buffers = {
          asio::buffer(*out_frame_.head),
          out_frame_.payload ? asio::buffer(*out_frame_.payload) : asio::const_buffer()};
      ws_.async_write(buffers, [self](beast::error_code ec, std::size_t) { self->OnWrite(ec, 2); });
    } else {
      ws_.text(true);
      const int what = kind == Kind::kState ? 1 : 0;
      ws_.async_write(asio::buffer(*out_text_),
                      [self, what](beast::error_code ec, std::size_t) { self->OnWrite(ec, what); });
    }
  }

  // `what`: 0 text, 1 state, 2 frame.
  void OnWrite(beast::error_code ec, int what) {
    {
      std::lock_guard lock(mutex_);
      writing_ = false;
      queued_bytes_ -= in_flight_bytes_;
      in_flight_bytes_ = 0;
      if (!ec) {
        if (what == 1) ++stats_.states_sent;
        if (what == 2) ++stats_.frames_sent;
      }
    }
    out_text_.reset();
    out_frame_ = Frame{};
    if (ec) {
      Close();
      return;
    }
    MaybeWrite();
  }

  ServerCore* server_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer read_buffer_;
  std::optional<int64_t> last_id_;  // I/O thread only

  // The message being written (I/O thread only, while writing_).
  Text out_text_;
  Frame out_frame_;

  mutable std::mutex mutex_;  // everything below
  ClientStats stats_;
  std::deque<Text> texts_;
  Text state_;
  std::map<std::string, Frame> frames_;
  std::string last_camera_;
  std::size_t queued_bytes_ = 0;  // texts_, state_, frames_ and the write in flight
  std::size_t in_flight_bytes_ = 0;
  bool open_ = false;
  bool closed_ = false;
  bool writing_ = false;
  bool kick_pending_ = false;
};

// ---------------------------------------------------------------------------------------------
// HTTP session
// ---------------------------------------------------------------------------------------------

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(ServerCore* server, tcp::socket socket)
      : server_(server), stream_(std::move(socket)) {}

  void Run() { DoRead(); }

  void Close() {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
    stream_.close();
  }

 private:
  using Request = http::request<http::string_body>;

  void DoRead() {
    parser_.emplace();
    parser_->body_limit(kHttpBodyLimit);
    stream_.expires_after(kHttpTimeout);
    http::async_read(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->OnRead(ec); });
  }

  void OnRead(beast::error_code ec) {
    if (ec || server_->stopping) {
      Close();
      return;
    }
    Handle(parser_->release());
  }

  // Writes `response` (its Content-Length already set when `prepare` is false, as for HEAD),
  // then reads the next request unless the connection ends.
  template <class Body>
  void Send(http::response<Body>&& response, bool prepare = true) {
    auto res = std::make_shared<http::response<Body>>(std::move(response));
    res->set(http::field::server, kServerName);
    if (prepare) res->prepare_payload();
    http::async_write(stream_, *res,
                      [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
                        if (ec || res->need_eof() || self->server_->stopping) {
                          self->Close();
                          return;
                        }
                        self->DoRead();
                      });
  }

  // A response from memory; HEAD gets the headers with the body's length and no body.
  void SendText(const Request& req, http::status status, std::string body,
                const std::string& content_type = "text/plain; charset=utf-8",
                bool no_store = false) {
    if (req.method() == http::verb::head) {
      http::response<http::empty_body> res{status, req.version()};
      res.set(http::field::content_type, content_type);
      if (no_store) res.set(http::field::cache_control, "no-store");
      res.keep_alive(req.keep_alive());
      res.content_length(body.size());
      Send(std::move(res), false);
      return;
    }
    http::response<http::string_body> res{status, req.version()};
    res.set(http::field::content_type, content_type);
    if (no_store) res.set(http::field::cache_control, "no-store");
    res.keep_alive(req.keep_alive());
    res.body() = std::move(body);
    Send(std::move(res));
  }

  void Handle(Request req) {
    ServerCore& server = *server_;
    const std::string_view target = View(req.target());
    const std::size_t question = target.find('?');
    const std::string_view raw_path = target.substr(0, question);
    const std::string_view query =
        question == std::string_view::npos ? std::string_view() : target.substr(question + 1);
    std::string path;
    if (!PercentDecode(raw_path, &path) || path.empty() || path[0] != '/' ||
        path.find('\0') != std::string::npos) {
      SendText(req, http::status::bad_request, "bad request target\n");
      return;
    }
    // Only this server's own page, by name (Host) and origin (Origin), before anything else:
    // see gui_server.h, "Security".
    {
      const auto host_field = req.find(http::field::host);
      const std::string_view host =
          host_field == req.end() ? std::string_view() : View(host_field->value());
      const auto origin_field = req.find(http::field::origin);
      const bool has_origin = origin_field != req.end();
      std::string why;
      if (!internal::HostAllowed(host, server.host_policy, &why) ||
          !internal::OriginAllowed(has_origin ? View(origin_field->value()) : std::string_view(),
                                   has_origin, host, &why)) {
        SendForbidden(req, path, why);
        return;
      }
    }
    const bool is_api = path == "/api" || path.starts_with("/api/");
    const bool is_ws = path == "/ws";
    const bool needs_token = !server.options.token.empty() && (is_api || is_ws);

    if (websocket::is_upgrade(req)) {
      if (!is_ws) {
        SendText(req, http::status::not_found, "WebSocket connections are served at /ws only\n");
        return;
      }
      if (needs_token && !server.TokenOk(req, query)) {
        SendUnauthorized(req);
        return;
      }
      Upgrade(std::move(req));
      return;
    }
    if (req.method() != http::verb::get && req.method() != http::verb::head) {
      http::response<http::string_body> res{http::status::method_not_allowed, req.version()};
      res.set(http::field::allow, "GET, HEAD");
      res.set(http::field::content_type, "text/plain; charset=utf-8");
      res.keep_alive(req.keep_alive());
      res.body() = "405: only GET and HEAD are served\n";
      Send(std::move(res));
      return;
    }
    if (needs_token && !server.TokenOk(req, query)) {
      SendUnauthorized(req);
      return;
    }
    if (is_ws) {
      SendText(req, http::status::bad_request, "/ws takes WebSocket connections only\n");
      return;
    }
    std::shared_ptr<const Document> document;
    {
      std::lock_guard lock(server.config_mutex);
      const auto it = server.documents.find(path);
      if (it != server.documents.end()) document = it->second;
    }
    if (document) {
      SendText(req, http::status::ok, document->body, document->content_type, is_api);
      return;
    }
    if (path == "/api/status") {
      json status = {
          {"protocol", kProtocolName}, {"version", kProtocolVersion}, {"clients", json::array()}};
      for (const auto& session : server.Snapshot()) {
        status["clients"].push_back(StatsJson(session->stats()));
      }
      SendText(req, http::status::ok, status.dump(), "application/json", true);
      return;
    }
    if (is_api) {
      SendText(req, http::status::not_found, "404: no such document: " + path + "\n",
               "text/plain; charset=utf-8", true);
      return;
    }
    ServeFile(req, path);
  }

  void SendForbidden(const Request& req, const std::string& path, const std::string& why) {
    beast::error_code ec;
    const tcp::endpoint peer = stream_.socket().remote_endpoint(ec);
    log::Warn("GUI server: 403 for {} ({} {}): {}",
              ec ? std::string("an unknown peer") : EndpointText(peer),
              std::string(View(req.method_string())), path, why);
    http::response<http::string_body> res{http::status::forbidden, req.version()};
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    res.set(http::field::cache_control, "no-store");
    res.keep_alive(false);
    res.body() = "403: " + why + "\n";
    Send(std::move(res));
  }

  void SendUnauthorized(const Request& req) {
    http::response<http::string_body> res{http::status::unauthorized, req.version()};
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    res.set(http::field::www_authenticate, "Bearer");
    res.set(http::field::cache_control, "no-store");
    res.keep_alive(req.keep_alive());
    res.body() =
        "401: a token is required (?token=TOKEN in the URL or the header "
        "Authorization: Bearer TOKEN)\n";
    Send(std::move(res));
  }

  void ServeFile(const Request& req, const std::string& path) {
    const auto& mounts = server_->mounts;
    const std::pair<std::string, fs::path>* mount = nullptr;
    for (const auto& m : mounts) {
      if (path.starts_with(m.first) && (!mount || m.first.size() > mount->first.size())) {
        mount = &m;
      }
    }
    const auto not_found = [&] {
      SendText(req, http::status::not_found, "404: not found: " + path + "\n");
    };
    if (!mount) {
      not_found();
      return;
    }
    std::string relative = path.substr(mount->first.size());
    if (relative.empty() || relative.back() == '/') relative += "index.html";
    std::error_code ec;
    const fs::path file = fs::weakly_canonical(mount->second / fs::path(relative), ec);
    if (ec || !IsInside(file, mount->second) || !fs::is_regular_file(file, ec)) {
      not_found();
      return;
    }
    const std::string content_type = ContentType(file);
    if (req.method() == http::verb::head) {
      const auto size = fs::file_size(file, ec);
      if (ec) {
        not_found();
        return;
      }
      http::response<http::empty_body> res{http::status::ok, req.version()};
      res.set(http::field::content_type, content_type);
      res.content_length(size);
      res.keep_alive(req.keep_alive());
      Send(std::move(res), false);
      return;
    }
    http::file_body::value_type body;
    beast::error_code open_ec;
    body.open(file.c_str(), beast::file_mode::scan, open_ec);
    if (open_ec) {
      not_found();
      return;
    }
    http::response<http::file_body> res{std::piecewise_construct, std::make_tuple(std::move(body)),
                                        std::make_tuple(http::status::ok, req.version())};
    res.set(http::field::content_type, content_type);
    res.keep_alive(req.keep_alive());
    Send(std::move(res));
  }

  void Upgrade(Request req) {
    ServerCore& server = *server_;
    std::shared_ptr<WsSession> session;
    {
      std::lock_guard lock(server.clients_mutex);
      if (static_cast<int>(server.clients.size()) < server.options.max_clients) {
        const int64_t id = server.next_client_id++;
        stream_.expires_never();
        session = std::make_shared<WsSession>(server_, stream_.release_socket(), id);
        server.clients.emplace(id, session);
      }
    }
    if (!session) {
      SendText(req, http::status::service_unavailable,
               "503: too many clients (max_clients " + std::to_string(server.options.max_clients) +
                   ")\n");
      return;
    }
    session->Run(std::move(req));
  }

  ServerCore* server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

// ---------------------------------------------------------------------------------------------
// Server
// ---------------------------------------------------------------------------------------------

bool ServerCore::TokenOk(const http::request<http::string_body>& req,
                         std::string_view query) const {
  const std::string& token = options.token;
  if (token.empty()) return true;
  if (const auto value = QueryValue(query, "token"); value && SameSecret(*value, token)) {
    return true;
  }
  const auto it = req.find(http::field::authorization);
  if (it != req.end()) {
    const std::string_view value = View(it->value());
    constexpr std::string_view kBearer = "Bearer ";
    if (value.size() > kBearer.size() &&
        beast::iequals(beast::string_view(value.data(), kBearer.size()), "Bearer ") &&
        SameSecret(value.substr(kBearer.size()), token)) {
      return true;
    }
  }
  return false;
}

void ServerCore::DoAccept() {
  acceptor->async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (stopping || !acceptor->is_open()) return;
    if (!ec) {
      // Small messages (states, replies) go out at once rather than after a delayed ACK.
      beast::error_code option_ec;
      socket.set_option(tcp::no_delay(true), option_ec);
      std::erase_if(http_sessions, [](const auto& weak) { return weak.expired(); });
      auto session = std::make_shared<HttpSession>(this, std::move(socket));
      http_sessions.push_back(session);
      session->Run();
    }
    DoAccept();
  });
}

void ServerCore::CloseAll() {
  stopping = true;
  beast::error_code ec;
  if (acceptor) acceptor->close(ec);
  for (const auto& weak : http_sessions) {
    if (auto session = weak.lock()) session->Close();
  }
  http_sessions.clear();
  for (const auto& session : Snapshot()) session->Close();
}

}  // namespace internal_gui

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
  if (o.max_message_bytes == 0 || o.max_clients < 1 || o.max_queued_messages == 0) {
    throw InvalidArgument(
        "GuiServer: max_message_bytes, max_clients and max_queued_messages must be positive, got " +
        std::to_string(o.max_message_bytes) + ", " + std::to_string(o.max_clients) + ", " +
        std::to_string(o.max_queued_messages));
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
