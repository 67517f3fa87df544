#include "saccade/core/log.h"
#include "server/internal_ws_session.h"

namespace saccade::server::internal_gui {

WsSession::WsSession(ServerCore* server, tcp::socket socket, int64_t id)
    : server_(server), ws_(std::move(socket)) {
  stats_.id = id;
  boost::system::error_code ec;
  const auto endpoint = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
  if (!ec) stats_.peer = EndpointText(endpoint);
}

void WsSession::Run(http::request<http::string_body> req) {
  beast::get_lowest_layer(ws_).expires_after(server_->options.http_timeout);
  ws_.set_option(websocket::stream_base::decorator(
      [](websocket::response_type& res) { res.set(http::field::server, kServerName); }));
  ws_.read_message_max(server_->options.max_message_bytes * kHardMessageFactor);
  ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) { self->OnAccept(ec); });
}

void WsSession::OfferState(const Text& state) {
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

void WsSession::OfferLatest(const std::string& kind, const Text& text) {
  bool kick = false;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    Text& slot = latest_[kind];
    if (slot) queued_bytes_ -= slot->size();
    slot = text;
    queued_bytes_ += text->size();
    kick = NeedsKickLocked();
  }
  if (kick) PostKick();
}

void WsSession::OfferFrame(const std::string& camera, const Frame& frame) {
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

void WsSession::OfferText(const Text& text) {
  bool kick = false;
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    QueueTextLocked(text);
    kick = NeedsKickLocked();
  }
  if (kick) PostKick();
}

ClientStats WsSession::stats() const {
  std::lock_guard lock(mutex_);
  ClientStats s = stats_;
  s.queued_bytes = queued_bytes_;
  return s;
}

void WsSession::Close() {
  {
    std::lock_guard lock(mutex_);
    if (closed_) return;
    closed_ = true;
    texts_.clear();
    state_.reset();
    latest_.clear();
    frames_.clear();
    queued_bytes_ = in_flight_bytes_;
  }
  server_->RemoveClient(stats_.id);
  beast::error_code ec;
  beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
  beast::get_lowest_layer(ws_).close();
}

void WsSession::OnAccept(beast::error_code ec) {
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
  std::map<std::string, Text> latest_of_kind;
  {
    std::lock_guard lock(server_->config_mutex);
    welcome = server_->welcome;
    latest_state = server_->latest_state;
    latest_of_kind = server_->latest_of_kind;
  }
  std::vector<Text> texts{std::make_shared<const std::string>(
      hello.dump(-1, ' ', false, json::error_handler_t::replace))};
  if (welcome) {
    try {
      for (std::string& text : welcome()) {
        texts.push_back(std::make_shared<const std::string>(std::move(text)));
      }
    } catch (const std::exception& e) {
      const json event = {
          {"type", "event"}, {"level", "error"}, {"message", std::string("welcome: ") + e.what()}};
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
    for (const auto& [kind, text] : latest_of_kind) {
      if (latest_.try_emplace(kind, text).second) queued_bytes_ += text->size();
    }
    open_ = true;
  }
  MaybeWrite();
  DoRead();
}

void WsSession::DoRead() {
  ws_.async_read(read_buffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    self->OnRead(ec);
  });
}

void WsSession::OnRead(beast::error_code ec) {
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

void WsSession::HandleCommand(std::string_view text) {
  ParsedCommand parsed = ParseCommand(text, last_id_);
  if (!parsed.ok()) {
    SendError(std::move(parsed.error_id), parsed.error);
    return;
  }
  const json& command = parsed.command;
  const json id = parsed.id;
  const int64_t id_value = parsed.id;
  last_id_ = id_value;

  // The session answers flow control itself; everything else goes to the application.
  const std::string& type = command.at("type").get_ref<const std::string&>();
  const bool flow = type == "frame_window" || type == "frame_ack";
  CommandHandler handler;
  if (!flow) {
    std::lock_guard lock(server_->config_mutex);
    handler = server_->handler;
  }
  if (!flow && !handler) {
    SendError(id, "this server takes no commands (no command handler)");
    return;
  }
  json reply;
  try {
    json result = flow ? FlowCommand(type, command) : handler(command, stats_.id);
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

json WsSession::FlowCommand(const std::string& type, const json& command) {
  const auto it = command.find("frames");
  const bool integer = it != command.end() && it->is_number_integer() &&
                       !(it->is_number_unsigned() && it->get<uint64_t>() > (uint64_t{1} << 62));
  std::lock_guard lock(mutex_);
  if (type == "frame_window") {
    if (!integer || it->get<int64_t>() < 0 || it->get<int64_t>() > kMaxFrameWindow) {
      throw CommandError("frame_window: 'frames' must be an integer from 0 (no window) to " +
                         std::to_string(kMaxFrameWindow) + ", got " +
                         (it == command.end() ? std::string("nothing") : it->dump()));
    }
    stats_.frame_window = it->get<int>();
  } else {
    if (!integer) {
      throw CommandError(
          "frame_ack: 'frames' must be an integer, the running total of frames this client "
          "has finished with, got " +
          (it == command.end() ? std::string("nothing") : it->dump()));
    }
    const int64_t total = it->get<int64_t>();
    if (total < stats_.frames_acked) {
      throw CommandError("frame_ack: 'frames' " + std::to_string(total) + " is fewer than the " +
                         std::to_string(stats_.frames_acked) +
                         " already acknowledged (it is a running total)");
    }
    if (total > frames_written_) {
      throw CommandError("frame_ack: 'frames' " + std::to_string(total) + " is more than the " +
                         std::to_string(frames_written_) + " frames sent to this client");
    }
    stats_.frames_acked = total;
  }
  return json{{"window", stats_.frame_window},
              {"frames_sent", frames_written_},
              {"frames_acked", stats_.frames_acked}};
}

bool WsSession::FrameRoomLocked() const {
  return stats_.frame_window == 0 || frames_written_ - stats_.frames_acked < stats_.frame_window;
}

void WsSession::SendError(json id, const std::string& message) {
  {
    std::lock_guard lock(mutex_);
    ++stats_.errors;
  }
  QueueOwnText(json{{"type", "error"}, {"id", std::move(id)}, {"error", message}});
}

void WsSession::QueueOwnText(const json& message) {
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

bool WsSession::IsClosed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

void WsSession::QueueTextLocked(const Text& text) {
  while (!texts_.empty() && texts_.size() >= server_->options.max_queued_messages) {
    DropOldestLocked();
  }
  texts_.push_back(text);
  queued_bytes_ += text->size();
}

void WsSession::DropOldestLocked() {
  queued_bytes_ -= texts_.front()->size();
  texts_.pop_front();
  ++stats_.messages_dropped;
}

bool WsSession::NeedsKickLocked() {
  if (!open_ || closed_ || writing_ || kick_pending_) return false;
  kick_pending_ = true;
  return true;
}

void WsSession::PostKick() {
  asio::post(ws_.get_executor(), [self = shared_from_this()] {
    {
      std::lock_guard lock(self->mutex_);
      self->kick_pending_ = false;
    }
    self->MaybeWrite();
  });
}

void WsSession::MaybeWrite() {
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
    } else if (!latest_.empty()) {
      kind = Kind::kText;
      out_text_ = std::move(latest_.begin()->second);
      latest_.erase(latest_.begin());
      in_flight_bytes_ = out_text_->size();
    } else if (!frames_.empty() && FrameRoomLocked()) {
      kind = Kind::kFrame;
      ++frames_written_;
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

void WsSession::OnWrite(beast::error_code ec, int what) {
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

}  // namespace saccade::server::internal_gui
