#pragma once
// An HTTP connection to the GUI server: access checks, documents and static files (GET and
// HEAD), and the upgrade of /ws to a WebSocket session.
#include "server/internal_server_core.h"

namespace saccade::server::internal_gui {

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(ServerCore* server, tcp::socket socket);

  // I/O thread: reads requests until the connection ends.
  void Run();
  // I/O thread: closes the connection at once.
  void Close();

 private:
  using Request = http::request<http::string_body>;

  void DoRead();

  void OnRead(beast::error_code ec);

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
                bool no_store = false);

  void Handle(Request req);

  void SendForbidden(const Request& req, const std::string& path, const std::string& why);

  void SendUnauthorized(const Request& req);

  void ServeFile(const Request& req, const std::string& path);

  void Upgrade(Request req);

  ServerCore* server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

}  // namespace saccade::server::internal_gui
