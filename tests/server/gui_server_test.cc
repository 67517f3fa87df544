// The GUI server (issue 6, docs/gui-protocol.md): static files and documents over HTTP, the
// token, the WebSocket hello, command validation and replies, and the per-client bounds that
// keep a slow client from slowing the publisher or growing without limit. Real sockets on
// ephemeral ports, real files in temporary folders; clients are Beast's, driven with timeouts.

#include "saccade/server/gui_server.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "server/internal_access.h"

namespace saccade::server {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace fs = std::filesystem;
using tcp = asio::ip::tcp;
using nlohmann::json;

// Waits only for events to happen, never to bound how long they take.
constexpr auto kWait = std::chrono::seconds(10);

std::string Str(beast::string_view v) { return std::string(v.data(), v.size()); }

// Runs `ioc` until `done` or kWait; false on timeout.
bool RunUntil(asio::io_context& ioc, const bool& done) {
  ioc.restart();
  const auto deadline = std::chrono::steady_clock::now() + kWait;
  while (!done && std::chrono::steady_clock::now() < deadline) {
    ioc.run_one_for(std::chrono::milliseconds(100));
    if (ioc.stopped()) ioc.restart();
  }
  return done;
}

// A folder tree with real files, removed at the end.
class TempTree {
 public:
  TempTree() {
    static std::atomic<int> counter{0};
    root_ = fs::temp_directory_path() /
            ("saccade_gui_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(root_);
  }
  ~TempTree() {
    std::error_code ec;
    fs::remove_all(root_, ec);
  }
  fs::path Write(const std::string& relative, const std::string& bytes) const {
    const fs::path path = root_ / relative;
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }
  fs::path path(const std::string& relative = "") const { return root_ / relative; }

 private:
  fs::path root_;
};

struct HttpResult {
  int status = 0;
  std::string body;
  std::string content_type;
  std::string cache_control;
  std::string content_length;
};

// One keep-alive HTTP connection.
class HttpClient {
 public:
  explicit HttpClient(uint16_t port) : stream_(ioc_) {
    stream_.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  }

  std::optional<HttpResult> Request(http::verb method, const std::string& target,
                                    const std::map<http::field, std::string>& headers = {}) {
    http::request<http::string_body> req{method, target, 11};
    req.set(http::field::host, "127.0.0.1");
    for (const auto& [field, value] : headers) req.set(field, value);
    req.prepare_payload();
    http::write(stream_, req);
    http::response_parser<http::string_body> parser;
    parser.body_limit(64 * 1024 * 1024);
    if (method == http::verb::head) parser.skip(true);
    bool done = false;
    beast::error_code ec;
    http::async_read(stream_, buffer_, parser, [&](beast::error_code e, std::size_t) {
      ec = e;
      done = true;
    });
    if (!RunUntil(ioc_, done) || ec) return std::nullopt;
    const auto& res = parser.get();
    HttpResult out;
    out.status = res.result_int();
    out.body = res.body();
    if (res.count(http::field::content_type))
      out.content_type = Str(res[http::field::content_type]);
    if (res.count(http::field::cache_control)) {
      out.cache_control = Str(res[http::field::cache_control]);
    }
    if (res.count(http::field::content_length)) {
      out.content_length = Str(res[http::field::content_length]);
    }
    return out;
  }

  HttpResult Get(const std::string& target,
                 const std::map<http::field, std::string>& headers = {}) {
    auto result = Request(http::verb::get, target, headers);
    EXPECT_TRUE(result.has_value()) << "no answer to GET " << target;
    return result.value_or(HttpResult{});
  }

 private:
  asio::io_context ioc_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
};

HttpResult Get(uint16_t port, const std::string& target,
               const std::map<http::field, std::string>& headers = {}) {
  HttpClient client(port);
  return client.Get(target, headers);
}

struct Message {
  bool text = true;
  std::string data;
};

// A WebSocket client.
class WsClient {
 public:
  WsClient() : ws_(ioc_) {}

  // The handshake's HTTP status: 101 when it succeeded. `host` is the Host header sent;
  // `origin`, when not empty, the Origin header (as a browser sends it).
  int Connect(uint16_t port, const std::string& target = "/ws", const std::string& bearer = "",
              const std::string& host = "127.0.0.1", const std::string& origin = "") {
    beast::get_lowest_layer(ws_).connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    ws_.set_option(
        websocket::stream_base::decorator([bearer, origin](websocket::request_type& req) {
          if (!bearer.empty()) req.set(http::field::authorization, "Bearer " + bearer);
          if (!origin.empty()) req.set(http::field::origin, origin);
        }));
    ws_.read_message_max(64 * 1024 * 1024);
    websocket::response_type res;
    bool done = false;
    ws_.async_handshake(res, host, target, [&](beast::error_code, ...) { done = true; });
    if (!RunUntil(ioc_, done)) return -1;
    return res.result_int();
  }

  std::optional<Message> Read() {
    beast::flat_buffer buffer;
    bool done = false;
    beast::error_code ec;
    ws_.async_read(buffer, [&](beast::error_code e, std::size_t) {
      ec = e;
      done = true;
    });
    if (!RunUntil(ioc_, done)) {
      beast::get_lowest_layer(ws_).close();
      ioc_.restart();
      ioc_.run();
      return std::nullopt;
    }
    if (ec) {
      last_error_ = ec;
      return std::nullopt;
    }
    return Message{ws_.got_text(), beast::buffers_to_string(buffer.data())};
  }

  // The next text message of `type` (others skipped); null on timeout or close.
  json ReadType(const std::string& type) {
    for (;;) {
      const auto message = Read();
      if (!message) return nullptr;
      if (!message->text) continue;
      json parsed = json::parse(message->data);
      if (parsed.value("type", "") == type) return parsed;
    }
  }

  // The next reply or error.
  json ReadAnswer() {
    for (;;) {
      const auto message = Read();
      if (!message) return nullptr;
      if (!message->text) continue;
      json parsed = json::parse(message->data);
      const std::string type = parsed.value("type", "");
      if (type == "reply" || type == "error") return parsed;
    }
  }

  void Send(const std::string& text, bool binary = false) {
    ws_.binary(binary);
    ws_.write(asio::buffer(text));
  }
  void SendJson(const json& command) { Send(command.dump()); }

  beast::error_code last_error() const { return last_error_; }
  websocket::close_reason close_reason() const { return ws_.reason(); }

 private:
  asio::io_context ioc_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::error_code last_error_;
};

ServerOptions LocalOptions() {
  ServerOptions options;
  options.port = 0;
  return options;
}

// A server with a command handler that echoes and a few commands that fail.
class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override { Make(LocalOptions()); }

  void Make(ServerOptions options) {
    server_.reset();
    server_ = std::make_unique<GuiServer>(std::move(options));
    server_->SetCommandHandler([this](const json& command, int64_t client) -> json {
      ++handled_;
      const std::string type = command.at("type");
      if (type == "refuse") throw CommandError("joints: pan 2.50 rad is outside its limits");
      if (type == "crash") throw std::runtime_error("out of cheese");
      return json{{"echo", type}, {"client", client}};
    });
    server_->Start();
  }

  std::unique_ptr<WsClient> Connect() {
    auto client = std::make_unique<WsClient>();
    EXPECT_EQ(client->Connect(server_->port()), 101);
    EXPECT_EQ(client->ReadType("hello").value("type", ""), "hello");
    return client;
  }

  std::unique_ptr<GuiServer> server_;
  std::atomic<int> handled_{0};
};

// ------------------------------------------------------------------------------------------
// HTTP
// ------------------------------------------------------------------------------------------

class StaticFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tree_.Write("web/index.html", "<!doctype html><title>saccade</title>");
    tree_.Write("web/app/main.js", "console.log('hi');");
    tree_.Write("web/app/style.css", "body{}");
    png_ = std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16);
    tree_.Write("web/img/eye.png", png_);
    tree_.Write("web/data.xyz", "raw");
    tree_.Write("web/vendor/three/three.module.js", "wrong folder");
    tree_.Write("three/three.module.js", "export const REVISION = '160';");
    tree_.Write("outside/secret.txt", "secret");
    fs::create_symlink(tree_.path("outside/secret.txt"), tree_.path("web/link.txt"));
    fs::create_symlink("app/main.js", tree_.path("web/inside_link.js"));
    ServerOptions options = LocalOptions();
    options.mounts = {{"/", tree_.path("web").string()},
                      {"/vendor/three/", tree_.path("three").string()}};
    server_ = std::make_unique<GuiServer>(options);
    server_->Start();
  }

  TempTree tree_;
  std::string png_;
  std::unique_ptr<GuiServer> server_;
};

TEST_F(StaticFilesTest, ServesFileBytesWithContentType) {
  const HttpResult js = Get(server_->port(), "/app/main.js");
  EXPECT_EQ(js.status, 200);
  EXPECT_EQ(js.body, "console.log('hi');");
  EXPECT_EQ(js.content_type.rfind("text/javascript", 0), 0u) << js.content_type;

  const HttpResult png = Get(server_->port(), "/img/eye.png");
  EXPECT_EQ(png.status, 200);
  EXPECT_EQ(png.body, png_);
  EXPECT_EQ(png.content_type, "image/png");

  EXPECT_EQ(Get(server_->port(), "/app/style.css").content_type.rfind("text/css", 0), 0u);
  EXPECT_EQ(Get(server_->port(), "/data.xyz").content_type, "application/octet-stream");
}

TEST_F(StaticFilesTest, RootServesIndexHtml) {
  const HttpResult root = Get(server_->port(), "/");
  EXPECT_EQ(root.status, 200);
  EXPECT_EQ(root.body, "<!doctype html><title>saccade</title>");
  EXPECT_EQ(root.content_type.rfind("text/html", 0), 0u);
  EXPECT_EQ(Get(server_->port(), "/?token=ignored").body, root.body);
}

TEST_F(StaticFilesTest, LongestPrefixMountServes) {
  const HttpResult three = Get(server_->port(), "/vendor/three/three.module.js");
  EXPECT_EQ(three.status, 200);
  EXPECT_EQ(three.body, "export const REVISION = '160';");
}

TEST_F(StaticFilesTest, PercentEncodedPathIsDecoded) {
  EXPECT_EQ(Get(server_->port(), "/app/%6Dain.js?v=3").body, "console.log('hi');");
}

TEST_F(StaticFilesTest, MissingFileIs404) {
  EXPECT_EQ(Get(server_->port(), "/nope.js").status, 404);
  EXPECT_EQ(Get(server_->port(), "/app/").status, 404);  // no index.html there
}

TEST_F(StaticFilesTest, PathsLeavingTheMountAre404) {
  // The targets exist outside the mount: 404 means refused, not missing.
  EXPECT_EQ(Get(server_->port(), "/../outside/secret.txt").status, 404);
  EXPECT_EQ(Get(server_->port(), "/%2e%2e/outside/secret.txt").status, 404);
  EXPECT_EQ(Get(server_->port(), "/app/..%2F..%2Foutside/secret.txt").status, 404);
  EXPECT_EQ(Get(server_->port(), "/vendor/three/../../outside/secret.txt").status, 404);
  const HttpResult link = Get(server_->port(), "/link.txt");
  EXPECT_EQ(link.status, 404);
  EXPECT_EQ(link.body.find("secret"), std::string::npos);
  // A symlink that stays inside is fine.
  EXPECT_EQ(Get(server_->port(), "/inside_link.js").body, "console.log('hi');");
}

TEST_F(StaticFilesTest, OnlyGetAndHeadAreServed) {
  HttpClient client(server_->port());
  const auto post = client.Request(http::verb::post, "/index.html");
  ASSERT_TRUE(post.has_value());
  EXPECT_EQ(post->status, 405);
  const auto head = client.Request(http::verb::head, "/index.html");
  ASSERT_TRUE(head.has_value());
  EXPECT_EQ(head->status, 200);
  EXPECT_EQ(head->content_length, "37");
  EXPECT_TRUE(head->body.empty());
}

TEST_F(StaticFilesTest, KeepAliveServesSeveralRequestsOnOneConnection) {
  HttpClient client(server_->port());
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(client.Get("/app/main.js").body, "console.log('hi');");
  }
}

TEST(GuiServerHttpTest, DocumentsAreServedExactlyWithTheirType) {
  GuiServer server(LocalOptions());
  const std::string binary("\x01\x00\x02\xff", 4);
  server.SetDocument("/api/scene", "application/json", R"({"name":"portraits.yaml"})");
  server.SetDocument("/api/models/0.bin", "application/octet-stream", binary);
  server.Start();
  const HttpResult scene = Get(server.port(), "/api/scene");
  EXPECT_EQ(scene.status, 200);
  EXPECT_EQ(scene.body, R"({"name":"portraits.yaml"})");
  EXPECT_EQ(scene.content_type, "application/json");
  EXPECT_EQ(scene.cache_control, "no-store");
  EXPECT_EQ(Get(server.port(), "/api/models/0.bin").body, binary);
  EXPECT_EQ(Get(server.port(), "/api/models/1.bin").status, 404);
  server.SetDocument("/api/scene", "application/json", "{}");
  EXPECT_EQ(Get(server.port(), "/api/scene").body, "{}");
}

TEST(GuiServerHttpTest, StatusListsClients) {
  GuiServer server(LocalOptions());
  server.Start();
  WsClient client;
  ASSERT_EQ(client.Connect(server.port()), 101);
  ASSERT_FALSE(client.ReadType("hello").is_null());
  const HttpResult status = Get(server.port(), "/api/status");
  ASSERT_EQ(status.status, 200);
  EXPECT_EQ(status.cache_control, "no-store");
  const json body = json::parse(status.body);
  EXPECT_EQ(body.at("protocol"), kProtocolName);
  EXPECT_EQ(body.at("version"), kProtocolVersion);
  ASSERT_EQ(body.at("clients").size(), 1u);
  EXPECT_EQ(body["clients"][0]["peer"].get<std::string>().rfind("127.0.0.1:", 0), 0u);
  EXPECT_TRUE(body["clients"][0].contains("frames_skipped"));
  EXPECT_EQ(body["clients"][0].value("frame_window", -1), 0);
  EXPECT_EQ(body["clients"][0].value("frames_acked", -1), 0);
}

TEST(GuiServerHttpTest, WebSocketOnlyAtWs) {
  GuiServer server(LocalOptions());
  server.Start();
  WsClient elsewhere;
  EXPECT_EQ(elsewhere.Connect(server.port(), "/socket"), 404);
  EXPECT_EQ(Get(server.port(), "/ws").status, 400);  // not an upgrade
}

// ------------------------------------------------------------------------------------------
// Options and the token
// ------------------------------------------------------------------------------------------

TEST(GuiServerOptionsTest, NonLoopbackAddressWithoutTokenThrowsNamingTheToken) {
  ServerOptions options = LocalOptions();
  options.address = "0.0.0.0";
  try {
    GuiServer server(options);
    FAIL() << "no exception";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("--token"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("0.0.0.0"), std::string::npos) << e.what();
  }
  options.token = "t";
  EXPECT_NO_THROW(GuiServer server(options));
}

TEST(GuiServerOptionsTest, BadMountsThrowNamingTheMount) {
  TempTree tree;
  fs::create_directories(tree.path("web"));
  ServerOptions options = LocalOptions();
  options.mounts = {{"/app", tree.path("web").string()}};
  try {
    GuiServer server(options);
    FAIL() << "no exception";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("'/app'"), std::string::npos) << e.what();
  }
  options.mounts = {{"/app/", tree.path("missing").string()}};
  try {
    GuiServer server(options);
    FAIL() << "no exception";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
}

TEST(GuiServerOptionsTest, LoopbackAddresses) {
  EXPECT_TRUE(IsLoopbackAddress("127.0.0.1"));
  EXPECT_TRUE(IsLoopbackAddress("127.3.2.1"));
  EXPECT_TRUE(IsLoopbackAddress("::1"));
  EXPECT_TRUE(IsLoopbackAddress("localhost"));
  EXPECT_FALSE(IsLoopbackAddress("0.0.0.0"));
  EXPECT_FALSE(IsLoopbackAddress("192.168.1.2"));
  EXPECT_FALSE(IsLoopbackAddress("::"));
  EXPECT_FALSE(IsLoopbackAddress("example.org"));
}

TEST(GuiServerOptionsTest, UrlNamesPortAndToken) {
  ServerOptions options = LocalOptions();
  GuiServer plain(options);
  plain.Start();
  EXPECT_EQ(plain.url(), "http://127.0.0.1:" + std::to_string(plain.port()) + "/");
  EXPECT_NE(plain.port(), 0);
  options.token = "s3cret";
  GuiServer with_token(options);
  with_token.Start();
  EXPECT_EQ(with_token.url(),
            "http://127.0.0.1:" + std::to_string(with_token.port()) + "/?token=s3cret");
}

TEST(GuiServerOptionsTest, StartOnAPortInUseThrowsNamingThePort) {
  GuiServer first(LocalOptions());
  first.Start();
  ServerOptions options = LocalOptions();
  options.port = first.port();
  GuiServer second(options);
  try {
    second.Start();
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(first.port())), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("127.0.0.1"), std::string::npos) << e.what();
  }
}

class TokenTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tree_.Write("web/index.html", "page");
    ServerOptions options = LocalOptions();
    options.token = "s3cret";
    options.mounts = {{"/", tree_.path("web").string()}};
    server_ = std::make_unique<GuiServer>(options);
    server_->SetDocument("/api/scene", "application/json", "{}");
    server_->Start();
  }
  TempTree tree_;
  std::unique_ptr<GuiServer> server_;
};

TEST_F(TokenTest, WebSocketWithoutTokenIs401) {
  WsClient client;
  EXPECT_EQ(client.Connect(server_->port(), "/ws"), 401);
  WsClient wrong;
  EXPECT_EQ(wrong.Connect(server_->port(), "/ws?token=guess"), 401);
  EXPECT_EQ(server_->client_count(), 0);
}

TEST_F(TokenTest, WebSocketWithQueryTokenConnects) {
  WsClient client;
  ASSERT_EQ(client.Connect(server_->port(), "/ws?token=s3cret"), 101);
  EXPECT_EQ(client.ReadType("hello").value("type", ""), "hello");
}

TEST_F(TokenTest, WebSocketWithBearerHeaderConnects) {
  WsClient client;
  ASSERT_EQ(client.Connect(server_->port(), "/ws", "s3cret"), 101);
  EXPECT_EQ(client.ReadType("hello").value("type", ""), "hello");
}

TEST_F(TokenTest, ApiNeedsTheTokenStaticFilesDoNot) {
  const HttpResult refused = Get(server_->port(), "/api/status");
  EXPECT_EQ(refused.status, 401);
  EXPECT_NE(refused.body.find("token"), std::string::npos) << refused.body;
  EXPECT_EQ(Get(server_->port(), "/api/scene").status, 401);
  EXPECT_EQ(Get(server_->port(), "/api/status?token=s3cret").status, 200);
  EXPECT_EQ(
      Get(server_->port(), "/api/scene", {{http::field::authorization, "Bearer s3cret"}}).body,
      "{}");
  EXPECT_EQ(
      Get(server_->port(), "/api/scene", {{http::field::authorization, "Bearer nope"}}).status,
      401);
  const HttpResult page = Get(server_->port(), "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_EQ(page.body, "page");
}

// ------------------------------------------------------------------------------------------
// WebSocket: hello, commands, errors
// ------------------------------------------------------------------------------------------

// ---------------------------------------------------------------------------------------------
// Access: only this server's own page (issue 18: a page of another origin drove the head).
// ---------------------------------------------------------------------------------------------

TEST(GuiServerAccessTest, HostNamesAreLowerCaseWithoutPortOrBrackets) {
  EXPECT_EQ(internal::HostName("Example.COM:8080"), "example.com");
  EXPECT_EQ(internal::HostName("127.0.0.1"), "127.0.0.1");
  EXPECT_EQ(internal::HostName("[::1]:80"), "::1");
  EXPECT_EQ(internal::HostName("::1"), "");  // IPv6 needs brackets in a Host header
  EXPECT_EQ(internal::HostName("[::1"), "");
  EXPECT_EQ(internal::HostName("evil.com/x"), "");
  EXPECT_EQ(internal::HostName("127.0.0.1:8080@evil.com"), "");
  EXPECT_EQ(internal::HostName(""), "");
}

TEST(GuiServerAccessTest, HostPolicyAcceptsLoopbackTheListenAddressAndAllowedNamesOnly) {
  std::string why;
  const internal::HostPolicy loopback{"127.0.0.1", {}, 8080};
  for (const char* host :
       {"127.0.0.1:8080", "localhost:8080", "LOCALHOST", "127.1.2.3", "[::1]:8080", "[::1]"}) {
    EXPECT_TRUE(internal::HostAllowed(host, loopback, &why)) << host << ": " << why;
  }
  for (const char* host : {"evil.example.com:8080", "192.168.1.20:8080", "localhost.evil.com",
                           "127.0.0.1.evil.com", ""}) {
    EXPECT_FALSE(internal::HostAllowed(host, loopback, &why)) << host;
  }
  EXPECT_FALSE(internal::HostAllowed("evil.example.com:8080", loopback, &why));
  EXPECT_THAT(why, ::testing::HasSubstr("'evil.example.com:8080' is not this server"));

  const internal::HostPolicy lab{"192.168.1.20", {"robot-head.local"}, 8080};
  EXPECT_TRUE(internal::HostAllowed("192.168.1.20:8080", lab, &why));
  EXPECT_TRUE(internal::HostAllowed("Robot-Head.local:8080", lab, &why));
  EXPECT_FALSE(internal::HostAllowed("192.168.1.21:8080", lab, &why));
  EXPECT_FALSE(internal::HostAllowed("robot-head.local.evil.com", lab, &why));

  // On every interface: any address literal (a page from one is this server's own), no name.
  const internal::HostPolicy any{"0.0.0.0", {}, 8080};
  EXPECT_TRUE(internal::HostAllowed("10.1.2.3:8080", any, &why));
  EXPECT_TRUE(internal::HostAllowed("[fe80::1]:8080", any, &why));
  EXPECT_FALSE(internal::HostAllowed("rebind.evil.com:8080", any, &why));
}

// Issue 46: the check read only the text before the first ':', so a Host with userinfo or a
// port followed by junk named this server.
TEST(GuiServerAccessTest, AHostThatIsNotExactlyHostAndThisPortIsRefused) {
  std::string why;
  const internal::HostPolicy policy{"127.0.0.1", {"robot-head.local"}, 8080};
  for (const char* host : {"127.0.0.1:8080@evil.example.com",
                           "user@127.0.0.1:8080",
                           "user:pass@localhost:8080",
                           "[::ffff:7f00:1]:8080x",
                           "127.0.0.1:8080x",
                           "127.0.0.1:",
                           "[::1]:",
                           "localhost:+8080",
                           "localhost: 8080",
                           "127.0.0.1:8080:8080",
                           "127.0.0.1:123456",
                           "[::1]x",
                           "[::1]]:8080",
                           "[127.0.0.1]:8080",
                           "[fe80::1%25eth0]:8080",
                           "[localhost]:8080",
                           "127.0.0.1/x",
                           "127.0.0.1:8080/x",
                           ":8080",
                           "127.0.0.1 :8080",
                           "robot-head.local:8080@evil.example.com"}) {
    EXPECT_FALSE(internal::HostAllowed(host, policy, &why)) << host;
    EXPECT_THAT(why, ::testing::HasSubstr("is malformed (expected host[:port]")) << host;
  }
  for (const char* host : {"127.0.0.1:9090", "localhost:80", "[::1]:8081", "127.0.0.1:08080",
                           "127.0.0.1:80800", "robot-head.local:443", "127.0.0.1:0"}) {
    EXPECT_FALSE(internal::HostAllowed(host, policy, &why)) << host;
    EXPECT_THAT(why, ::testing::HasSubstr("not this server's port 8080")) << host;
  }
  // Still this server: with or without the port, by any loopback form or an allowed name.
  for (const char* host :
       {"127.0.0.1:8080", "127.0.0.1", "localhost:8080", "[::1]:8080", "[::ffff:7f00:1]:8080",
        "[::FFFF:127.0.0.1]", "robot-head.local:8080", "robot-head.local"}) {
    EXPECT_TRUE(internal::HostAllowed(host, policy, &why)) << host << ": " << why;
  }
  ASSERT_TRUE(internal::ParseHostHeader("[::1]:8080").has_value());
  EXPECT_EQ(internal::ParseHostHeader("[::1]:8080")->host, "::1");
  EXPECT_EQ(internal::ParseHostHeader("[::1]:8080")->port, "8080");
  EXPECT_FALSE(internal::ParseHostHeader("localhost")->has_port);
}

TEST(GuiServerAccessTest, OriginMustBeThePageOfTheHostAsked) {
  std::string why;
  EXPECT_TRUE(internal::OriginAllowed("", false, "127.0.0.1:8080", &why));  // not a browser
  EXPECT_TRUE(internal::OriginAllowed("http://127.0.0.1:8080", true, "127.0.0.1:8080", &why));
  EXPECT_TRUE(internal::OriginAllowed("http://LocalHost:8080", true, "localhost:8080", &why));
  EXPECT_FALSE(internal::OriginAllowed("http://evil.example.com", true, "127.0.0.1:8080", &why));
  EXPECT_THAT(why, ::testing::HasSubstr("'http://evil.example.com'"));
  EXPECT_FALSE(internal::OriginAllowed("http://127.0.0.1:9090", true, "127.0.0.1:8080", &why));
  EXPECT_FALSE(internal::OriginAllowed("https://127.0.0.1:8080", true, "127.0.0.1:8080", &why));
  EXPECT_FALSE(internal::OriginAllowed("null", true, "127.0.0.1:8080", &why));
  EXPECT_FALSE(internal::OriginAllowed("", true, "127.0.0.1:8080", &why));
}

TEST(GuiServerAccessTest, GeneratedTokensAre128RandomBitsInHex) {
  const std::string a = GenerateToken();
  const std::string b = GenerateToken();
  EXPECT_EQ(a.size(), 32u);
  EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos) << a;
  EXPECT_NE(a, b);
}

TEST(GuiServerAccessTest, AnAllowedHostThatIsNotANameThrowsNamingIt) {
  ServerOptions options = LocalOptions();
  options.allowed_hosts = {"http://robot-head.local:8080"};
  try {
    GuiServer server(options);
    FAIL() << "no exception";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("'http://robot-head.local:8080'"));
  }
}

class AccessTest : public ServerTest {};

TEST_F(AccessTest, AForeignHostIs403OnThePageTheApiAndTheWebSocketAndIsLogged) {
  const std::string evil = "evil.example.com:" + std::to_string(server_->port());
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(Get(server_->port(), "/api/status", {{http::field::host, evil}}).status, 403);
  const HttpResult page = Get(server_->port(), "/", {{http::field::host, evil}});
  EXPECT_EQ(page.status, 403);
  EXPECT_THAT(page.body, ::testing::HasSubstr("Host 'evil.example.com"));
  WsClient ws;
  EXPECT_EQ(ws.Connect(server_->port(), "/ws", "", evil, "http://" + evil), 403);
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(log, ::testing::HasSubstr("403 for 127.0.0.1:"));
  EXPECT_THAT(log, ::testing::HasSubstr("(GET /ws): the Host 'evil.example.com"));
  EXPECT_EQ(server_->client_count(), 0);
}

TEST_F(AccessTest, AWebSocketFromAnotherOriginIs403AndNoCommandArrives) {
  const std::string host = "127.0.0.1:" + std::to_string(server_->port());
  for (const std::string origin : {"http://evil.example.com", "null", "http://127.0.0.1:1"}) {
    WsClient ws;
    EXPECT_EQ(ws.Connect(server_->port(), "/ws", "", host, origin), 403) << origin;
  }
  EXPECT_EQ(handled_, 0);
  EXPECT_EQ(server_->client_count(), 0);
  // The page's own origin, by address or by name, and a script that sends no Origin, connect.
  WsClient own, by_name, script;
  EXPECT_EQ(own.Connect(server_->port(), "/ws", "", host, "http://" + host), 101);
  const std::string named = "localhost:" + std::to_string(server_->port());
  EXPECT_EQ(by_name.Connect(server_->port(), "/ws", "", named, "http://" + named), 101);
  EXPECT_EQ(script.Connect(server_->port()), 101);
}

TEST_F(AccessTest, AllowedHostNamesAreServed) {
  ServerOptions options = LocalOptions();
  options.allowed_hosts = {"robot-head.local"};
  Make(options);
  const std::string host = "robot-head.local:" + std::to_string(server_->port());
  EXPECT_EQ(Get(server_->port(), "/api/status", {{http::field::host, host}}).status, 200);
  WsClient ws;
  EXPECT_EQ(ws.Connect(server_->port(), "/ws", "", host, "http://" + host), 101);
  EXPECT_EQ(Get(server_->port(), "/api/status", {{http::field::host, "other.local"}}).status, 403);
}

TEST_F(AccessTest, AHostWithUserinfoOrAnotherPortIs403OnTheApiAndTheWebSocket) {
  const std::string port = std::to_string(server_->port());
  const std::string other = std::to_string(server_->port() == 65535 ? 65534 : server_->port() + 1);
  ::testing::internal::CaptureStderr();
  for (const std::string& host :
       {"127.0.0.1:" + port + "@evil.example.com", "[::ffff:7f00:1]:" + port + "x",
        "evil@127.0.0.1:" + port, "127.0.0.1:" + other, "localhost:" + other,
        std::string("127.0.0.1:"), "127.0.0.1:" + port + "x"}) {
    EXPECT_EQ(Get(server_->port(), "/api/status", {{http::field::host, host}}).status, 403) << host;
    WsClient ws;
    EXPECT_EQ(ws.Connect(server_->port(), "/ws", "", host), 403) << host;
  }
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(log,
              ::testing::HasSubstr("names port " + other + ", not this server's port " + port));
  EXPECT_EQ(server_->client_count(), 0);
  EXPECT_EQ(handled_, 0);
  for (const std::string& host :
       {"127.0.0.1:" + port, "localhost:" + port, "[::1]:" + port, std::string("127.0.0.1")}) {
    EXPECT_EQ(Get(server_->port(), "/api/status", {{http::field::host, host}}).status, 200) << host;
  }
  WsClient ws;
  const std::string host = "127.0.0.1:" + port;
  EXPECT_EQ(ws.Connect(server_->port(), "/ws", "", host, "http://" + host), 101);
}

TEST(GuiServerWsTest, HelloCarriesProtocolClientAndExtraFieldsThenWelcome) {
  ServerOptions options = LocalOptions();
  options.hello = {{"mode", "demo"}};
  GuiServer server(options);
  server.SetWelcome([] { return std::vector<std::string>{R"({"type":"state","step":7})"}; });
  server.Start();
  WsClient client;
  ASSERT_EQ(client.Connect(server.port()), 101);
  const auto first = client.Read();
  ASSERT_TRUE(first.has_value());
  ASSERT_TRUE(first->text);
  const json hello = json::parse(first->data);
  EXPECT_EQ(hello.at("type"), "hello");
  EXPECT_EQ(hello.at("protocol"), "saccade-gui");
  EXPECT_EQ(hello.at("version"), kProtocolVersion);
  EXPECT_EQ(hello.at("mode"), "demo");
  const int64_t id = hello.at("client");
  EXPECT_GT(id, 0);
  const auto second = client.Read();
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(json::parse(second->data).at("step"), 7);
  const auto stats = server.clients();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].id, id);
}

TEST_F(ServerTest, CommandReachesHandlerAndReplyCarriesIdAndFields) {
  auto client = Connect();
  client->SendJson(json{{"type", "ping"}, {"id", 1}});
  const json reply = client->ReadAnswer();
  EXPECT_EQ(reply.at("type"), "reply");
  EXPECT_EQ(reply.at("id"), 1);
  EXPECT_EQ(reply.at("ok"), true);
  EXPECT_EQ(reply.at("echo"), "ping");
  EXPECT_EQ(reply.at("client"), server_->clients().at(0).id);
  EXPECT_EQ(handled_, 1);
}

TEST_F(ServerTest, HandlerErrorsBecomeErrorReplies) {
  auto client = Connect();
  client->SendJson(json{{"type", "refuse"}, {"id", 1}});
  const json refused = client->ReadAnswer();
  EXPECT_EQ(refused.at("type"), "error");
  EXPECT_EQ(refused.at("id"), 1);
  EXPECT_EQ(refused.at("error"), "joints: pan 2.50 rad is outside its limits");
  client->SendJson(json{{"type", "crash"}, {"id", 2}});
  const json crashed = client->ReadAnswer();
  EXPECT_EQ(crashed.at("error"), "out of cheese");
  client->SendJson(json{{"type", "ping"}, {"id", 3}});
  EXPECT_EQ(client->ReadAnswer().at("type"), "reply");
}

TEST(GuiServerWsTest, WithoutHandlerEveryCommandIsAnError) {
  GuiServer server(LocalOptions());
  server.Start();
  WsClient client;
  ASSERT_EQ(client.Connect(server.port()), 101);
  client.SendJson(json{{"type", "ping"}, {"id", 1}});
  const json answer = client.ReadAnswer();
  EXPECT_EQ(answer.at("type"), "error");
  EXPECT_EQ(answer.at("id"), 1);
  EXPECT_NE(answer.at("error").get<std::string>().find("handler"), std::string::npos);
}

struct BadMessage {
  std::string name;
  std::function<void(WsClient&)> send;
  std::string expected;  // part of the error text
};

TEST_F(ServerTest, BadMessagesGetErrorRepliesAndEveryoneGoesOn) {
  auto client = Connect();
  auto other = Connect();
  int64_t id = 0;
  // Sets the connection's last id to 5 for the out-of-order case.
  client->SendJson(json{{"type", "ping"}, {"id", 5}});
  ASSERT_EQ(client->ReadAnswer().at("id"), 5);
  id = 5;
  const std::vector<BadMessage> cases = {
      {"malformed", [](WsClient& c) { c.Send("{\"type\": \"ping\", "); }, "malformed JSON: "},
      {"not an object", [](WsClient& c) { c.Send("[1, 2]"); }, "JSON object"},
      {"deeply nested",
       [](WsClient& c) { c.Send(std::string(30000, '[') + std::string(30000, ']')); },
       "nested 30000 levels deep"},
      {"missing type",
       [](WsClient& c) {
         c.SendJson(json{{"id", 100}});
       },
       "'type'"},
      {"type not a string",
       [](WsClient& c) {
         c.SendJson(json{{"type", 3}, {"id", 100}});
       },
       "'type'"},
      {"missing id",
       [](WsClient& c) {
         c.SendJson(json{{"type", "ping"}});
       },
       "'id'"},
      {"id not an integer",
       [](WsClient& c) {
         c.SendJson(json{{"type", "ping"}, {"id", "7"}});
       },
       "'id'"},
      {"out of order",
       [](WsClient& c) {
         c.SendJson(json{{"type", "ping"}, {"id", 3}});
       },
       "out of order: id 3 after "},
      {"repeated id",
       [](WsClient& c) {
         c.SendJson(json{{"type", "ping"}, {"id", 5}});
       },
       "out of order: id 5 after "},
      {"binary", [](WsClient& c) { c.Send("{}", true); }, "binary messages are not commands"},
      {"too large", [](WsClient& c) { c.Send(std::string(100 * 1024, ' ')); },
       "message of 102400 bytes is larger than the limit of 65536 bytes"},
  };
  int step = 0;
  for (const BadMessage& bad : cases) {
    SCOPED_TRACE(bad.name);
    bad.send(*client);
    const json error = client->ReadAnswer();
    ASSERT_FALSE(error.is_null());
    EXPECT_EQ(error.at("type"), "error");
    EXPECT_NE(error.at("error").get<std::string>().find(bad.expected), std::string::npos)
        << error.dump();
    // The same connection still answers, and the other client still gets states.
    client->SendJson(json{{"type", "ping"}, {"id", ++id}});
    const json reply = client->ReadAnswer();
    EXPECT_EQ(reply.value("type", ""), "reply");
    EXPECT_EQ(reply.value("id", 0), id);
    server_->PublishState({{"type", "state"}, {"step", ++step}});
    EXPECT_EQ(other->ReadType("state").value("step", 0), step);
  }
  const auto stats = server_->clients();
  int64_t errors = 0;
  for (const auto& s : stats) errors += s.errors;
  EXPECT_EQ(errors, static_cast<int64_t>(cases.size()));
}

TEST_F(ServerTest, OutOfOrderErrorCarriesTheId) {
  auto client = Connect();
  client->SendJson(json{{"type", "ping"}, {"id", 5}});
  client->ReadAnswer();
  client->SendJson(json{{"type", "ping"}, {"id", 3}});
  const json error = client->ReadAnswer();
  EXPECT_EQ(error.at("id"), 3);
  EXPECT_EQ(error.at("error"), "out of order: id 3 after 5");
}

TEST_F(ServerTest, MessageBeyondTheHardBoundClosesWithTooBig) {
  auto client = Connect();
  auto other = Connect();
  client->Send(std::string(64 * 1024 * 16 + 1, ' '));
  EXPECT_FALSE(client->ReadAnswer().is_object());  // closed
  EXPECT_EQ(client->close_reason().code, websocket::close_code::too_big);
  server_->PublishState({{"type", "state"}, {"step", 1}});
  EXPECT_EQ(other->ReadType("state").value("step", 0), 1);
}

// ------------------------------------------------------------------------------------------
// Fan-out and bounds
// ------------------------------------------------------------------------------------------

TEST_F(ServerTest, ManyClientsAllReceiveTheNewestState) {
  std::vector<std::unique_ptr<WsClient>> clients;
  for (int i = 0; i < 20; ++i) clients.push_back(Connect());
  EXPECT_EQ(server_->client_count(), 20);
  for (int step = 1; step <= 50; ++step) server_->PublishState({{"type", "state"}, {"step", step}});
  server_->Broadcast({{"type", "event"}, {"level", "info"}, {"message", "done"}});
  // Texts go before the state, so the event may come first.
  for (auto& client : clients) {
    bool newest = false;
    bool event = false;
    while (!newest || !event) {
      const auto message = client->Read();
      ASSERT_TRUE(message.has_value());
      const json parsed = json::parse(message->data);
      if (parsed.at("type") == "state" && parsed.at("step") == 50) newest = true;
      if (parsed.at("type") == "event" && parsed.at("message") == "done") event = true;
    }
  }
}

// PublishLatest (the GUI's map): a client that does not read holds at most the newest message
// of the kind besides the one being written, never a queue of them; a client that connects later
// gets the newest.
TEST_F(ServerTest, LatestOfAKindReplacesTheUnsentAndReachesLateClients) {
  auto client = Connect();
  const std::string bulk(100 * 1024, 'x');  // 20 MB in all: more than the sockets hold
  constexpr int kMessages = 200;
  for (int n = 1; n <= kMessages; ++n) {
    server_->PublishLatest("map", {{"type", "map"}, {"n", n}, {"bulk", bulk}});
  }
  const std::vector<server::ClientStats> stats = server_->clients();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_LE(stats[0].queued_bytes, 2 * (bulk.size() + 100)) << "a queue of maps, not one slot";
  int received = 0, last = 0;
  while (last < kMessages) {
    const auto message = client->Read();
    ASSERT_TRUE(message.has_value());
    const json parsed = json::parse(message->data);
    if (parsed.at("type") != "map") continue;
    ++received;
    EXPECT_GT(parsed.at("n").get<int>(), last) << "in order, never an older one again";
    last = parsed.at("n").get<int>();
  }
  EXPECT_LT(received, kMessages) << "none replaced";
  auto late = Connect();
  EXPECT_EQ(late->ReadType("map").value("n", 0), kMessages);
}

// Parses a frame message: [uint32 LE n][n bytes JSON header][payload].
bool ParseFrame(const std::string& data, json* header, std::string* payload) {
  if (data.size() < 4) return false;
  const uint32_t n = static_cast<uint8_t>(data[0]) | static_cast<uint8_t>(data[1]) << 8 |
                     static_cast<uint8_t>(data[2]) << 16 |
                     static_cast<uint32_t>(static_cast<uint8_t>(data[3])) << 24;
  if (data.size() < 4 + n) return false;
  *header = json::parse(data.substr(4, n));
  *payload = data.substr(4 + n);
  return true;
}

TEST_F(ServerTest, SlowClientStaysBoundedWhileFastClientGetsFrames) {
  constexpr int kCount = 300;
  constexpr std::size_t kFrameBytes = 256 * 1024;
  // At most a frame in flight, two pending frames, a state and a few texts.
  constexpr std::size_t kBound = 3 * 1024 * 1024;

  WsClient slow;  // connects, never reads
  ASSERT_EQ(slow.Connect(server_->port()), 101);
  auto fast = Connect();

  std::atomic<bool> fast_ok{false};
  std::map<std::string, int> last_frame;
  std::string last_left_payload;
  int frames_received = 0;
  std::thread reader([&] {
    while (last_frame["left"] != kCount - 1 || last_frame["right"] != kCount - 1) {
      const auto message = fast->Read();
      if (!message) return;
      if (message->text) continue;
      json header;
      std::string payload;
      if (!ParseFrame(message->data, &header, &payload)) return;
      ++frames_received;
      last_frame[header.at("camera")] = header.at("frame");
      if (header.at("camera") == "left") last_left_payload = std::move(payload);
    }
    fast_ok = true;
  });

  const auto left = std::make_shared<const std::string>(kFrameBytes, 'L');
  const auto right = std::make_shared<const std::string>(kFrameBytes, 'R');
  std::size_t slow_max_queued = 0;
  for (int i = 0; i < kCount; ++i) {
    server_->PublishFrame("left", {{"type", "frame"}, {"camera", "left"}, {"frame", i}}, left);
    server_->PublishFrame("right", {{"type", "frame"}, {"camera", "right"}, {"frame", i}}, right);
    server_->PublishState({{"type", "state"}, {"step", i}});
    if (i % 10 == 0) server_->Broadcast({{"type", "event"}, {"message", std::to_string(i)}});
    for (const ClientStats& s : server_->clients()) {
      if (s.id == 1) slow_max_queued = std::max(slow_max_queued, s.queued_bytes);
    }
  }
  reader.join();
  EXPECT_TRUE(fast_ok) << "the fast client did not get the last frame of each camera";
  EXPECT_GT(frames_received, 0);
  EXPECT_EQ(last_left_payload, *left);

  const auto stats = server_->clients();
  ASSERT_EQ(stats.size(), 2u);
  const ClientStats& slow_stats = stats[0].id == 1 ? stats[0] : stats[1];
  ASSERT_EQ(slow_stats.id, 1);
  EXPECT_LT(slow_max_queued, kBound);
  EXPECT_LT(slow_stats.queued_bytes, kBound);
  EXPECT_GT(slow_stats.frames_skipped, 0);
  EXPECT_GT(slow_stats.states_skipped, 0);
}

TEST_F(ServerTest, TextQueueDropsOldestWhenFull) {
  ServerOptions options = LocalOptions();
  options.max_queued_messages = 4;
  Make(options);
  WsClient slow;  // never reads
  ASSERT_EQ(slow.Connect(server_->port()), 101);
  const std::string filler(64 * 1024, 'x');
  for (int i = 0; i < 400; ++i) {
    server_->Broadcast({{"type", "event"}, {"message", filler}});
  }
  // 400 x 64 KiB is far more than the socket buffers hold.
  const auto stats = server_->clients();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_GT(stats[0].messages_dropped, 0);
  EXPECT_LT(stats[0].queued_bytes, 6u * (filler.size() + 100));
}

// The next message that is a frame or an answer (states and events skipped): the frame's
// header, or the reply/error.
json NextFrameOrAnswer(WsClient& client) {
  for (;;) {
    const auto message = client.Read();
    if (!message) return nullptr;
    if (!message->text) {
      json header;
      std::string payload;
      if (!ParseFrame(message->data, &header, &payload)) return nullptr;
      return header;
    }
    json parsed = json::parse(message->data);
    const std::string type = parsed.value("type", "");
    if (type == "reply" || type == "error") return parsed;
  }
}

void PublishFrames(GuiServer& server, const std::string& camera, int first, int last) {
  const auto payload = std::make_shared<const std::string>(1000, camera[0]);
  for (int i = first; i <= last; ++i) {
    server.PublishFrame(camera, {{"type", "frame"}, {"camera", camera}, {"frame", i}}, payload);
  }
}

TEST_F(ServerTest, AFrameWindowHoldsFramesUntilAcknowledgedThenSendsTheNewest) {
  auto client = Connect();
  client->SendJson({{"type", "frame_window"}, {"id", 1}, {"frames", 1}});
  const json set = NextFrameOrAnswer(*client);
  EXPECT_EQ(set.at("type"), "reply");
  EXPECT_EQ(set.at("window"), 1);
  EXPECT_EQ(set.at("frames_sent"), 0);
  EXPECT_EQ(handled_, 0) << "flow control is the session's, not the application's";

  PublishFrames(*server_, "left", 0, 0);
  EXPECT_EQ(NextFrameOrAnswer(*client).value("frame", -1), 0);
  // The window is full: newer frames wait, each camera's newest replacing the one before, and
  // an answer overtakes them.
  PublishFrames(*server_, "left", 1, 5);
  PublishFrames(*server_, "right", 1, 2);
  client->SendJson({{"type", "ping"}, {"id", 2}});
  const json pong = NextFrameOrAnswer(*client);
  EXPECT_EQ(pong.value("type", ""), "reply") << pong.dump();
  EXPECT_EQ(pong.value("id", 0), 2);

  // Each acknowledgement lets one more through: the newest of a camera.
  client->SendJson({{"type", "frame_ack"}, {"id", 3}, {"frames", 1}});
  const json ack = NextFrameOrAnswer(*client);
  EXPECT_EQ(ack.value("type", ""), "reply") << ack.dump();
  EXPECT_EQ(ack.value("frames_sent", -1), 1);
  EXPECT_EQ(ack.value("frames_acked", -1), 1);
  std::map<std::string, int> got;
  const json first = NextFrameOrAnswer(*client);
  got[first.value("camera", "")] = first.value("frame", -1);
  client->SendJson({{"type", "frame_ack"}, {"id", 4}, {"frames", 2}});
  EXPECT_EQ(NextFrameOrAnswer(*client).value("frames_sent", -1), 2);
  const json second = NextFrameOrAnswer(*client);
  got[second.value("camera", "")] = second.value("frame", -1);
  EXPECT_EQ(got, (std::map<std::string, int>{{"left", 5}, {"right", 2}}));

  const ClientStats stats = server_->clients().at(0);
  EXPECT_EQ(stats.frame_window, 1);
  EXPECT_EQ(stats.frames_acked, 2);
  EXPECT_EQ(stats.frames_skipped, 5);  // left 1-4, right 1

  // Window 0 turns it off: frames flow without acknowledgements.
  client->SendJson({{"type", "frame_window"}, {"id", 5}, {"frames", 0}});
  EXPECT_EQ(NextFrameOrAnswer(*client).value("window", -1), 0);
  for (int i = 6; i < 9; ++i) {
    PublishFrames(*server_, "left", i, i);
    EXPECT_EQ(NextFrameOrAnswer(*client).value("frame", -1), i);
  }
}

TEST_F(ServerTest, BadFlowCommandsAreErrorsThatNameTheFieldAndChangeNothing) {
  auto client = Connect();
  client->SendJson({{"type", "frame_window"}, {"id", 1}, {"frames", 2}});
  ASSERT_EQ(NextFrameOrAnswer(*client).value("type", ""), "reply");
  PublishFrames(*server_, "left", 0, 0);
  ASSERT_EQ(NextFrameOrAnswer(*client).value("frame", -1), 0);

  const std::vector<std::pair<json, std::string>> bad = {
      {{{"type", "frame_window"}, {"frames", 65}}, "'frames' must be an integer from 0"},
      {{{"type", "frame_window"}, {"frames", -1}}, "got -1"},
      {{{"type", "frame_window"}, {"frames", "4"}}, "got \"4\""},
      {{{"type", "frame_window"}}, "got nothing"},
      {{{"type", "frame_ack"}, {"frames", 1.5}}, "running total"},
      {{{"type", "frame_ack"}, {"frames", 2}}, "'frames' 2 is more than the 1 frames sent"},
  };
  int64_t id = 2;
  for (const auto& [fields, expected] : bad) {
    json command = fields;
    command["id"] = id;
    client->SendJson(command);
    const json answer = NextFrameOrAnswer(*client);
    EXPECT_EQ(answer.value("type", ""), "error") << command.dump();
    EXPECT_EQ(answer.value("id", 0), id);
    const std::string error = answer.value("error", "");
    EXPECT_EQ(error.rfind(fields.at("type").get<std::string>() + ": ", 0), 0u) << error;
    EXPECT_NE(error.find(expected), std::string::npos) << error;
    ++id;
  }
  client->SendJson({{"type", "frame_ack"}, {"id", id++}, {"frames", 1}});
  ASSERT_EQ(NextFrameOrAnswer(*client).value("frames_acked", -1), 1);
  client->SendJson({{"type", "frame_ack"}, {"id", id++}, {"frames", 0}});
  EXPECT_NE(NextFrameOrAnswer(*client).value("error", "").find("fewer than the 1 already"),
            std::string::npos);

  const ClientStats stats = server_->clients().at(0);
  EXPECT_EQ(stats.frame_window, 2);
  EXPECT_EQ(stats.frames_acked, 1);
  EXPECT_EQ(handled_, 0);
}

TEST_F(ServerTest, ClientsBeyondMaxClientsGet503) {
  ServerOptions options = LocalOptions();
  options.max_clients = 2;
  Make(options);
  auto a = Connect();
  auto b = Connect();
  WsClient c;
  EXPECT_EQ(c.Connect(server_->port()), 503);
  EXPECT_EQ(server_->client_count(), 2);
}

TEST_F(ServerTest, StopWithConnectedClientsReturnsAndIsIdempotent) {
  auto a = Connect();
  WsClient slow;
  ASSERT_EQ(slow.Connect(server_->port()), 101);
  const auto payload = std::make_shared<const std::string>(1024 * 1024, 'x');
  for (int i = 0; i < 20; ++i) server_->PublishFrame("left", {{"frame", i}}, payload);
  server_->Stop();
  server_->Stop();
  EXPECT_EQ(server_->client_count(), 0);
  // The connection is gone: reads end.
  std::optional<Message> message;
  do {
    message = a->Read();
  } while (message.has_value());
  EXPECT_TRUE(a->last_error());
  // Publishing after Stop does nothing and does not block.
  server_->PublishState({{"type", "state"}});
  server_->Broadcast({{"type", "event"}});
}

}  // namespace
}  // namespace saccade::server
