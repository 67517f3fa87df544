#pragma once
// The browser GUI's server (issue 6): HTTP for the page and the files the scene uses,
// WebSocket for state, camera frames and commands. The protocol it speaks is
// docs/gui-protocol.md (version kProtocolVersion); this module knows nothing of heads or
// scenes: the application publishes state and frames, answers commands, and names the
// folders and documents served.
//
// Threads: the server runs its own I/O thread. Publish* and the accessors may be called from
// any thread and never block on a client: each client holds at most the newest state, the
// newest frame of each camera and a short queue of replies and events, so a slow client gets
// fewer frames, never a slower caller, and its memory stays bounded however slow it is.
// The command handler runs on the I/O thread; it must not block for long (queue the work).
//
// Security (docs/gui-protocol.md, "Security"): the threat is a web page of another origin
// that the operator happens to visit, which could otherwise open a WebSocket to the GUI on
// 127.0.0.1 and move the head (the real robot's servos with a hardware file), or read the
// scene through a DNS-rebinding name. So:
// - Every request must name this server in its Host header, exactly `host[:port]`: the host
//   localhost, a loopback address, the listen address (any IP address when listening on
//   0.0.0.0 or ::), or a name of `allowed_hosts`, IPv6 addresses in brackets; the port, when
//   given, this server's own. Anything else (another name or port, userinfo "h@evil", a
//   malformed port "8080x" or "h:", a path) gets 403 and a log line (core/log.h) naming the
//   peer. (A tunnel must keep the port number: ssh -L 8080:127.0.0.1:8080.)
// - A request that carries an Origin header (browsers send one on every WebSocket and on
//   cross-origin requests) must come from this server's own page: Origin equal to
//   "http://" + its Host. Anything else gets 403 and a log line. Programs that send no Origin
//   (scripts) are left to the token.
// - It listens on 127.0.0.1 unless told otherwise. Listening on any other address requires an
//   access token (the constructor throws without one). When a token is set, every WebSocket
//   connection and every /api/ request must present it (`?token=...` or the header
//   `Authorization: Bearer ...`), or gets 401. The page itself and static files need no token
//   (they hold no state). The applications set a random token (GenerateToken) on loopback too,
//   unless told not to, and print it in the page's address, as Jupyter does.
//
// Resources (ServerOptions): at most max_http_sessions HTTP connections (64) and max_clients
// WebSocket clients (32) at once; an HTTP connection idle for http_timeout (30 s) is closed.
// A local program that opens connections by the hundred cannot make the server use more file
// descriptors than these allow, and when the process runs out of them anyway (a low
// RLIMIT_NOFILE), a failed accept is retried after a back-off growing from 5 ms to 200 ms
// (reset by the next success, logged once per 10 s), not at once: the server does not spin,
// and accepts again as soon as descriptors are free.
//
// Messages larger than max_message_bytes, malformed JSON, a missing or unknown `type`, and ids
// that do not increase get an error reply naming what was wrong; the connection and every
// other client go on.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "saccade/core/error.h"

namespace saccade::server {

/// 2: poses as 4x4 nested rows (geometry/json.h), was 16 numbers in one list (issue 46).
inline constexpr int kProtocolVersion = 2;
inline constexpr const char* kProtocolName = "saccade-gui";

struct ServerOptions {
  std::string address = "127.0.0.1";  ///< listen address (IPv4 or IPv6 literal)
  uint16_t port = 8080;               ///< 0: any free port (see GuiServer::port)
  /// Access token; required (non-empty) when `address` is not a loopback address. When set,
  /// WebSocket connections and /api/ requests must present it.
  std::string token;
  /// Host names (no port) accepted in the Host header besides loopback names and addresses and
  /// the listen address, e.g. the machine's name on a lab network ("robot-head.local").
  std::vector<std::string> allowed_hosts;
  /// URL prefix ("/", "/vendor/three/") -> folder. The longest matching prefix serves; a
  /// path that leaves its folder (.., symlinks out) is 404. "/" serves index.html for "/".
  std::vector<std::pair<std::string, std::string>> mounts;
  /// Larger client messages get an error reply and are ignored; the connection stays open.
  /// Beyond 16 times this (a hard bound on what is read), the connection is closed with 1009.
  std::size_t max_message_bytes = 64 * 1024;
  /// WebSocket clients at once; a handshake beyond it gets 503. A client that sends nothing is
  /// never timed out (a page may only watch), so this bounds what they can hold.
  int max_clients = 32;
  /// HTTP connections at once (the page, files, /api/, WebSocket handshakes not yet upgraded;
  /// upgraded ones count against max_clients instead). A connection beyond it gets a 503 if
  /// its socket takes one at once and is closed; one log line per 10 s says how many were.
  int max_http_sessions = 64;
  /// An HTTP connection that does not deliver a whole request within this time after it opens
  /// or after its last response (an idle keep-alive, a request sent byte by byte, a WebSocket
  /// handshake that never completes) is closed.
  std::chrono::milliseconds http_timeout = std::chrono::seconds(30);
  std::size_t max_queued_messages = 64;  ///< replies and events per client; oldest dropped
  /// Fields merged into the hello message each client gets first ({"type": "hello",
  /// "protocol", "version", "client"} plus these, e.g. {"mode": "demo"}).
  nlohmann::json hello = nlohmann::json::object();
};

/// A command the handler refuses: the client gets {"type": "error", "id", "error": what}.
class CommandError : public Error {
 public:
  using Error::Error;
};

/// What one client has been sent and what it missed, for tests and the status line.
struct ClientStats {
  int64_t id = 0;
  std::string peer;  ///< "127.0.0.1:53122"
  int64_t states_sent = 0;
  int64_t states_skipped = 0;  ///< replaced by a newer state before it could be sent
  int64_t frames_sent = 0;
  int64_t frames_skipped = 0;    ///< replaced by a newer frame of the same camera
  int64_t messages_dropped = 0;  ///< replies and events dropped (queue full)
  int64_t commands = 0;          ///< commands received
  int64_t errors = 0;            ///< error replies sent
  std::size_t queued_bytes = 0;  ///< held for this client now
  /// Flow control (docs/gui-protocol.md, `frame_window`): at most this many frames sent and
  /// not yet acknowledged; 0 when the client asked for none (frames go as fast as it reads).
  int frame_window = 0;
  int64_t frames_acked = 0;  ///< the client's running total from `frame_ack`
};

/// Called for each well-formed command ({"type": ..., "id": ...}, a JSON object) on the I/O
/// thread. Returns the reply's fields (merged into {"type": "reply", "id": ..., "ok": true});
/// throws CommandError (or any std::exception) for an error reply. `client` is the id.
using CommandHandler = std::function<nlohmann::json(const nlohmann::json& command, int64_t client)>;

class GuiServer {
 public:
  /// Checks the options (InvalidArgument naming the option): a non-loopback address without a
  /// token, an unknown mount folder, a mount prefix that does not start and end with '/', a
  /// limit or timeout that is not positive.
  explicit GuiServer(ServerOptions options);
  ~GuiServer();  // Stop()
  GuiServer(const GuiServer&) = delete;
  GuiServer& operator=(const GuiServer&) = delete;

  /// Commands go to `handler` (set before Start). Without one, every command is an error.
  void SetCommandHandler(CommandHandler handler);
  /// Serves `body` at the exact `path` (e.g. "/api/scene"); replaces an earlier one. Paths
  /// under /api/ need the token when one is set.
  void SetDocument(const std::string& path, const std::string& content_type, std::string body);
  /// Sent to each client when it connects, after the hello (and before the newest published
  /// state, which every new client gets); called on the I/O thread.
  void SetWelcome(std::function<std::vector<std::string>()> welcome);

  /// Binds (port 0: any free port) and starts the I/O thread. Throws Error naming the address
  /// and port on failure (e.g. the port is in use), and when called a second time.
  void Start();
  /// Closes every connection (unsent messages are dropped) and joins the I/O thread;
  /// idempotent. A stopped server does not start again. Not from the command handler.
  void Stop();

  /// The bound port (after Start; the chosen one when options.port was 0).
  uint16_t port() const;
  /// "http://127.0.0.1:8080/" (with "?token=..." when a token is set).
  std::string url() const;

  /// The newest state (a JSON text message) for every client; replaces one not yet sent. A
  /// client that connects later gets it too, after the hello.
  void PublishState(const nlohmann::json& state);
  /// The newest frame of `camera` for every client: a binary message made of a 4-byte
  /// little-endian header length, the header (JSON) and the payload (JPEG). Replaces one of
  /// the same camera not yet sent. The payload is shared, never copied per client.
  void PublishFrame(const std::string& camera, const nlohmann::json& header,
                    std::shared_ptr<const std::string> payload);
  /// The newest message of `kind` (a JSON text, e.g. the map) for every client: replaces one
  /// of that kind not yet sent, so that a slow client holds at most one of each kind. A client
  /// that connects later gets it too, after the state. Sent after queued texts and the state,
  /// before frames.
  void PublishLatest(const std::string& kind, const nlohmann::json& message);
  /// An event (JSON text) queued for every client (oldest dropped when the queue is full).
  void Broadcast(const nlohmann::json& event);

  int client_count() const;
  std::vector<ClientStats> clients() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A fresh access token: 128 bits from the kernel's random source, as 32 hex digits. Throws
/// Error when the kernel gives none.
std::string GenerateToken();

/// True for 127.0.0.0/8, ::1 and "localhost".
bool IsLoopbackAddress(const std::string& address);

}  // namespace saccade::server
