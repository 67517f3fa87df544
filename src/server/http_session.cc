#include "saccade/core/log.h"
#include "server/internal_http_session.h"
#include "server/internal_ws_session.h"

namespace saccade::server::internal_gui {

HttpSession::HttpSession(ServerCore* server, tcp::socket socket)
    : server_(server), stream_(std::move(socket)) {}

void HttpSession::Run() { DoRead(); }

void HttpSession::Close() {
  beast::error_code ec;
  stream_.socket().shutdown(tcp::socket::shutdown_both, ec);
  stream_.close();
}

void HttpSession::DoRead() {
  parser_.emplace();
  parser_->body_limit(kHttpBodyLimit);
  stream_.expires_after(server_->options.http_timeout);
  http::async_read(
      stream_, buffer_, *parser_,
      [self = shared_from_this()](beast::error_code ec, std::size_t) { self->OnRead(ec); });
}

void HttpSession::OnRead(beast::error_code ec) {
  if (ec || server_->stopping) {
    Close();
    return;
  }
  Handle(parser_->release());
}

void HttpSession::SendText(const Request& req, http::status status, std::string body,
                           const std::string& content_type, bool no_store) {
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

void HttpSession::Handle(Request req) {
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

void HttpSession::SendForbidden(const Request& req, const std::string& path,
                                const std::string& why) {
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

void HttpSession::SendUnauthorized(const Request& req) {
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

void HttpSession::ServeFile(const Request& req, const std::string& path) {
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

void HttpSession::Upgrade(Request req) {
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
    SendText(
        req, http::status::service_unavailable,
        "503: too many clients (max_clients " + std::to_string(server.options.max_clients) + ")\n");
    return;
  }
  session->Run(std::move(req));
}

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
    if (ec) {
      OnAcceptError(ec);
      return;
    }
    accept_backoff = std::chrono::milliseconds(0);
    if (accept_warned) {
      log::Info("GUI server: accepting connections again");
      accept_warned = false;
    }
    std::erase_if(http_sessions, [](const auto& weak) { return weak.expired(); });
    if (static_cast<int>(http_sessions.size()) >= options.max_http_sessions) {
      Refuse(std::move(socket));
    } else {
      // Small messages (states, replies) go out at once rather than after a delayed ACK.
      beast::error_code option_ec;
      socket.set_option(tcp::no_delay(true), option_ec);
      auto session = std::make_shared<HttpSession>(this, std::move(socket));
      http_sessions.push_back(session);
      session->Run();
    }
    DoAccept();
  });
}

void ServerCore::OnAcceptError(beast::error_code ec) {
  if (ec == asio::error::connection_aborted) {
    DoAccept();  // the peer gave up before we took it: it left the backlog, nothing to wait for
    return;
  }
  accept_backoff = accept_backoff.count() == 0 ? kAcceptBackoffMin
                                               : std::min(accept_backoff * 2, kAcceptBackoffMax);
  ++accept_failures;
  const auto now = std::chrono::steady_clock::now();
  if (now - accept_logged >= kFloodLogInterval) {
    log::Warn(
        "GUI server: cannot accept a connection: {} ({} failed accepts since the last such line; "
        "{} HTTP connections, {} WebSocket clients open); retrying after pauses of up to {} ms",
        ec.message(), accept_failures, http_sessions.size(), Snapshot().size(),
        kAcceptBackoffMax.count());
    accept_logged = now;
    accept_failures = 0;
    accept_warned = true;
  }
  accept_timer.expires_after(accept_backoff);
  accept_timer.async_wait([this](beast::error_code wait_ec) {
    if (wait_ec || stopping || !acceptor->is_open()) return;
    DoAccept();
  });
}

void ServerCore::Refuse(tcp::socket socket) {
  // Best effort and never blocking: a fresh socket's send buffer takes this at once.
  static constexpr std::string_view kBusy =
      "HTTP/1.1 503 Service Unavailable\r\nContent-Type: text/plain; charset=utf-8\r\n"
      "Content-Length: 44\r\nConnection: close\r\n\r\n503: too many connections to the GUI "
      "server\n";
  beast::error_code ec;
  socket.non_blocking(true, ec);
  if (!ec) socket.write_some(asio::buffer(kBusy.data(), kBusy.size()), ec);
  socket.shutdown(tcp::socket::shutdown_both, ec);
  socket.close(ec);
  ++refused_sessions;
  const auto now = std::chrono::steady_clock::now();
  if (now - refusal_logged >= kFloodLogInterval) {
    log::Warn(
        "GUI server: {} HTTP connections open (max_http_sessions); closed {} more since the last "
        "such line",
        options.max_http_sessions, refused_sessions);
    refusal_logged = now;
    refused_sessions = 0;
  }
}

void ServerCore::CloseAll() {
  stopping = true;
  beast::error_code ec;
  accept_timer.cancel();
  if (acceptor) acceptor->close(ec);
  for (const auto& weak : http_sessions) {
    if (auto session = weak.lock()) session->Close();
  }
  http_sessions.clear();
  for (const auto& session : Snapshot()) session->Close();
}

}  // namespace saccade::server::internal_gui
