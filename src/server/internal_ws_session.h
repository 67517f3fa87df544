#pragma once
// A WebSocket client of the GUI server: the handshake, commands read and answered, and the
// writes of states, frames and texts, newest first, one in flight, and no more frames
// unacknowledged than the client's frame window (gui_server.cc, docs/gui-protocol.md).
#include "server/internal_server_core.h"

namespace saccade::server::internal_gui {

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(ServerCore* server, tcp::socket socket, int64_t id);

  int64_t id() const { return stats_.id; }

  // I/O thread: completes the handshake with the upgrade request already read.
  void Run(http::request<http::string_body> req);

  // Any thread: replaces the pending state.
  void OfferState(const Text& state);

  // Any thread: replaces the pending message of `kind` (GuiServer::PublishLatest).
  void OfferLatest(const std::string& kind, const Text& text);

  // Any thread: replaces the pending frame of `camera`.
  void OfferFrame(const std::string& camera, const Frame& frame);

  // Any thread: queues a text message, dropping the oldest when the queue is full.
  void OfferText(const Text& text);

  ClientStats stats() const;

  // I/O thread: closes the connection at once (pending writes are abandoned).
  void Close();

 private:
  void OnAccept(beast::error_code ec);

  void DoRead();

  void OnRead(beast::error_code ec);

  void HandleCommand(std::string_view text);

  // I/O thread: `frame_window` and `frame_ack`, which the session answers itself (the
  // application's handler never sees them). Returns the reply's fields; throws CommandError.
  json FlowCommand(const std::string& type, const json& command);

  // A frame may be written now: no window, or fewer than it sent and not acknowledged.
  bool FrameRoomLocked() const;

  void SendError(json id, const std::string& message);

  // I/O thread: queues a reply or error and starts a write when idle.
  void QueueOwnText(const json& message);

  bool IsClosed() const;

  void QueueTextLocked(const Text& text);

  void DropOldestLocked();

  bool NeedsKickLocked();

  void PostKick();

  // I/O thread: starts the next write when none is in flight.
  void MaybeWrite();

  // `what`: 0 text, 1 state, 2 frame.
  void OnWrite(beast::error_code ec, int what);

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
  std::map<std::string, Text> latest_;  // PublishLatest's, by kind
  std::map<std::string, Frame> frames_;
  std::string last_camera_;
  std::size_t queued_bytes_ = 0;  // texts_, state_, frames_ and the write in flight
  std::size_t in_flight_bytes_ = 0;
  int64_t frames_written_ = 0;  // frames whose write began (what `frame_ack` counts against)
  bool open_ = false;
  bool closed_ = false;
  bool writing_ = false;
  bool kick_pending_ = false;
};

}  // namespace saccade::server::internal_gui
