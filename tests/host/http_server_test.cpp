// The dashboard's HTTP server over loopback: every bound answers with its HTTP error, the access
// token and the Host/Origin rules hold, and event streams receive broadcasts.
#include "piezoshift/host/http_server.hpp"

#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <limits>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "../support/descriptor_exhaustion.hpp"
#include "../support/http_client.hpp"
#include "piezoshift/core/input_error.hpp"

namespace {

using piezoshift::host::HttpHandler;
using piezoshift::host::HttpRequest;
using piezoshift::host::HttpResponse;
using piezoshift::host::HttpServer;
using piezoshift::host::HttpServerOptions;
using piezoshift::testing::http_body;
using piezoshift::testing::http_exchange;
using piezoshift::testing::http_status;
using piezoshift::testing::HttpConnection;

// Answers "/" with the path and body it got; "/stream" opens a stream; broadcasts "tick" events.
class EchoHandler : public HttpHandler {
 public:
  HttpResponse on_request(const HttpRequest& r) override {
    if (r.path == "/stream") {
      HttpResponse s;
      s.stream = true;
      s.body = "retry: 1000\n\n";
      return s;
    }
    if (r.path != "/")
      return HttpResponse::text(404, "no");
    return HttpResponse::text(200, r.method + " " + r.path + " " + r.body);
  }
  void on_poll(HttpServer& server) override {
    if (++turns % 4 == 0)
      server.broadcast("event: tick\ndata: {}\n\n");
  }
  std::atomic<int> turns{0};
};

class Http : public ::testing::Test {
 protected:
  void start(HttpServerOptions o = {}) {
    server_ = std::make_unique<HttpServer>(o, handler_);
    thread_ = std::thread([this] { server_->run(nullptr, 2); });
  }
  void TearDown() override {
    if (server_) {
      server_->stop();
      thread_.join();
    }
  }
  std::string get(const std::string& target, const std::string& extra = "") {
    return http_exchange(server_->port(), "GET " + target + " HTTP/1.1\r\nHost: 127.0.0.1:" +
                                              std::to_string(server_->port()) + "\r\n" + extra +
                                              "\r\n");
  }
  std::string host() const { return "Host: 127.0.0.1:" + std::to_string(server_->port()) + "\r\n"; }

  EchoHandler handler_;
  std::unique_ptr<HttpServer> server_;
  std::thread thread_;
};

TEST_F(Http, AnswersAGetAndClosesTheConnection) {
  start();
  const std::string a = get("/");
  EXPECT_EQ(http_status(a), 200) << a;
  EXPECT_EQ(http_body(a), "GET / \n");
  EXPECT_NE(a.find("Connection: close"), std::string::npos);
  EXPECT_EQ(http_status(get("/nothing")), 404);
}

TEST_F(Http, MalformedRequestsGet400) {
  start();
  for (const std::string bad :
       {"GARBAGE\r\n\r\n", "GET / HTTP/9.9\r\n\r\n", "GET nopath HTTP/1.1\r\n\r\n",
        "GET / HTTP/1.1\r\nno colon\r\n\r\n", "GET /?a=%zz HTTP/1.1\r\n\r\n",
        "POST / HTTP/1.1\r\nContent-Length: x\r\n\r\n",
        "POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n"})
    EXPECT_EQ(http_status(http_exchange(server_->port(), bad)), 400) << bad;
}

// A second Content-Length was accepted, the last one winning; two parsers that take
// different ones see different requests (smuggling). One Content-Length (and one Host) or 400.
TEST_F(Http, ASecondContentLengthOrHostIsRefused) {
  start();
  const std::string json = "Content-Type: application/json\r\n";
  for (const std::string& twice :
       std::vector<std::string>{"Content-Length: 2\r\nContent-Length: 0\r\n",
                                "Content-Length: 2\r\ncontent-length: 2\r\n",
                                "Content-Length: 2\r\nTransfer-Encoding: identity\r\n", host()})
    EXPECT_EQ(http_status(http_exchange(server_->port(),
                                        "POST / HTTP/1.1\r\n" + host() + json + twice + "\r\n{}")),
              400)
        << twice;
  EXPECT_EQ(http_status(http_exchange(server_->port(), "POST / HTTP/1.1\r\n" + host() + json +
                                                           "Content-Length: 2\r\n\r\n{}")),
            200);
}

TEST_F(Http, OversizedHeadersGet431AndBodies413) {
  HttpServerOptions o;
  o.max_request_bytes = 1024;
  o.max_body_bytes = 100;
  start(o);
  EXPECT_EQ(http_status(get("/", "X-Big: " + std::string(2000, 'a') + "\r\n")), 431);
  // No end of headers at all, and still more than the limit: 431 without waiting for the rest.
  EXPECT_EQ(
      http_status(http_exchange(server_->port(), "GET / HTTP/1.1\r\n" + std::string(4000, 'b'))),
      431);
  const std::string post = "POST / HTTP/1.1\r\n" + host() +
                           "Content-Type: application/json\r\nContent-Length: 101\r\n\r\n" +
                           std::string(101, '{');
  EXPECT_EQ(http_status(http_exchange(server_->port(), post)), 413);
}

TEST_F(Http, AnIncompleteRequestTimesOutWith408) {
  HttpServerOptions o;
  o.request_timeout_s = 0.2;
  start(o);
  HttpConnection c(server_->port());
  c.send("GET / HTTP/1.1\r\nHost: x");
  const std::string a = c.read_all(3.0);
  EXPECT_EQ(http_status(a), 408) << a;
}

TEST_F(Http, OtherMethodsGet405) {
  start();
  EXPECT_EQ(http_status(http_exchange(server_->port(), "DELETE / HTTP/1.1\r\n" + host() + "\r\n")),
            405);
}

TEST_F(Http, WithoutATokenTheHostMustNameThisServer) {
  start();
  // DNS rebinding: a page of evil.example resolved to 127.0.0.1 still sends its own Host.
  EXPECT_EQ(http_status(
                http_exchange(server_->port(), "GET / HTTP/1.1\r\nHost: evil.example:80\r\n\r\n")),
            403);
  EXPECT_EQ(
      http_status(http_exchange(server_->port(), "GET / HTTP/1.1\r\nHost: localhost:" +
                                                     std::to_string(server_->port()) + "\r\n\r\n")),
      200);
}

TEST_F(Http, PostsMustBeJsonFromThisOrigin) {
  start();
  const std::string p = std::to_string(server_->port());
  const auto post = [&](const std::string& headers) {
    return http_status(http_exchange(
        server_->port(), "POST / HTTP/1.1\r\n" + host() + headers + "Content-Length: 2\r\n\r\n{}"));
  };
  EXPECT_EQ(post("Content-Type: text/plain\r\n"), 415);  // what a cross-site form can send
  EXPECT_EQ(post("Content-Type: application/json\r\nOrigin: http://evil.example\r\n"), 403);
  EXPECT_EQ(post("Content-Type: application/json\r\nOrigin: http://127.0.0.1:" + p + "\r\n"), 200);
  EXPECT_EQ(post("Content-Type: application/json\r\n"), 200);  // curl sends no Origin
  // A page on another localhost port is another origin, and so is the same port
  // named otherwise than the Host header names it, and a sandboxed page's "null".
  const std::string other = std::to_string(server_->port() == 65535 ? 1 : server_->port() + 1);
  for (const std::string& origin :
       std::vector<std::string>{"http://127.0.0.1:" + other, "http://localhost:" + other,
                                "http://localhost:" + p, "https://127.0.0.1:" + p, "null"})
    EXPECT_EQ(post("Content-Type: application/json\r\nOrigin: " + origin + "\r\n"), 403) << origin;
}

TEST_F(Http, ATokenIsRequiredOnEveryRequest) {
  HttpServerOptions o;
  o.token = "0123456789abcdef-secret";
  start(o);
  const std::string a = get("/");
  EXPECT_EQ(http_status(a), 401) << a;
  EXPECT_NE(a.find("WWW-Authenticate: Bearer"), std::string::npos);
  EXPECT_EQ(http_status(get("/", "Authorization: Bearer wrong\r\n")), 401);
  EXPECT_EQ(http_status(get("/?token=0123456789abcdef-secreT")), 401);
  EXPECT_EQ(http_status(get("/", "Authorization: Bearer 0123456789abcdef-secret\r\n")), 200);
  EXPECT_EQ(http_status(get("/?token=0123456789abcdef-secret")), 200);
  EXPECT_EQ(server_->stats().unauthorised, 3u);
}

TEST(HttpBind, ANonLoopbackAddressNeedsAToken) {
  EchoHandler h;
  HttpServerOptions o;
  o.host = "0.0.0.0";
  EXPECT_THROW(HttpServer(o, h), piezoshift::core::InputError);
  o.token = "0123456789abcdef";
  EXPECT_NO_THROW(HttpServer(o, h));
  o.host = "not-an-address";
  EXPECT_THROW(HttpServer(o, h), piezoshift::core::InputError);
}

TEST_F(Http, OneClientTooManyGets503) {
  HttpServerOptions o;
  o.max_clients = 2;
  // The refusal itself: no slot kept from streams, no room made (poll_server_test.cpp has those).
  o.reserved_for_requests = 0;
  o.evict_idle_when_full_s = std::numeric_limits<double>::infinity();
  start(o);
  HttpConnection a(server_->port());
  HttpConnection b(server_->port());
  a.send("GET /stream HTTP/1.1\r\n" + host() + "\r\n");
  b.send("GET /stream HTTP/1.1\r\n" + host() + "\r\n");
  std::string sa, sb;
  a.read_some(sa, 2.0);
  b.read_some(sb, 2.0);
  EXPECT_EQ(http_status(get("/")), 503);
}

TEST_F(Http, StreamsReceiveEveryBroadcast) {
  start();
  HttpConnection c(server_->port());
  c.send("GET /stream HTTP/1.1\r\n" + host() + "\r\n");
  std::string got;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (std::chrono::steady_clock::now() < end && got.find("event: tick") == std::string::npos)
    c.read_some(got, 0.1);
  EXPECT_EQ(http_status(got), 200);
  EXPECT_NE(got.find("Content-Type: text/event-stream"), std::string::npos);
  EXPECT_NE(got.find("event: tick\ndata: {}\n\n"), std::string::npos);
}

// Connections that arrive while the process has no descriptor left stay in the listen backlog,
// so the listening socket stays readable. At ebaef31 the server polled it again at once: a busy
// spin (one failed accept per turn) until a descriptor came free. Now it leaves the listener
// alone for 100 ms after each failure, keeps serving the clients it has, and accepts the waiting
// ones once descriptors are back.
TEST_F(Http, OutOfDescriptorsItPausesAcceptingAndServesTheClientsItHas) {
  start();
  HttpConnection stream(server_->port());
  stream.send("GET /stream HTTP/1.1\r\n" + host() + "\r\n");
  std::string before;
  ASSERT_TRUE(stream.read_some(before, 5.0));
  ASSERT_EQ(http_status(before), 200) << before;
  piezoshift::testing::WaitingClients waiting(3, server_->port());

  std::string during;
  int connected = 0;
  std::uint64_t failures = 0;
  double exhausted_s = 0.0;
  {
    const piezoshift::testing::DescriptorsExhausted exhausted;
    const auto t0 = std::chrono::steady_clock::now();
    connected = waiting.connect_all();  // the kernel completes these into the backlog
    while (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(500))
      stream.read_some(during, 0.05);
    failures = server_->stats().accept_failures;
    exhausted_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  EXPECT_EQ(connected, 3);
  // It ran out (at least one failed accept) and did not spin: at most one failure per 100 ms
  // pause, plus the first. A spinning server fails once per turn, thousands in 0.5 s.
  EXPECT_GE(failures, 1u);
  EXPECT_LE(static_cast<double>(failures), exhausted_s / 0.1 + 2.0)
      << failures << " failed accepts in " << exhausted_s << " s";
  // The stream it had kept receiving broadcasts meanwhile.
  EXPECT_NE(during.find("event: tick"), std::string::npos);
  // With descriptors back, the waiting clients are accepted and answered.
  for (int fd : waiting.fds()) {
    const std::string request = "GET / HTTP/1.1\r\n" + host() + "\r\n";
    ASSERT_EQ(::send(fd, request.data(), request.size(), MSG_NOSIGNAL),
              static_cast<ssize_t>(request.size()));
    std::string answer;
    char buf[4096];
    for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;)
      answer.append(buf, static_cast<std::size_t>(n));
    EXPECT_EQ(http_status(answer), 200) << answer;
  }
}

}  // namespace

namespace {

// "/later" is answered after `parts` calls of resume(), one per round; the others at once.
class LaterHandler : public HttpHandler {
 public:
  HttpResponse on_request(const HttpRequest& r) override {
    if (r.path != "/later")
      return HttpResponse::text(200, "now");
    remaining[r.client] = parts;
    return HttpResponse::deferred();
  }
  HttpResponse resume(std::uint64_t client) override {
    ++resumes;
    if (--remaining[client] > 0)
      return HttpResponse::deferred();
    remaining.erase(client);
    return HttpResponse::text(200, "later");
  }
  void abandon(std::uint64_t client) override {
    remaining.erase(client);
    ++abandoned;
  }
  int parts = 5;
  std::map<std::uint64_t, int> remaining;  // run() thread only
  std::atomic<int> resumes{0};
  std::atomic<int> abandoned{0};
};

}  // namespace

// A handler that answers in parts (a dashboard POST's GCS lines): resume() once per round until
// it answers, another request answered meanwhile; one not ready within the request timeout is
// abandoned and answered 503.
TEST(HttpLater, ADeferredRequestIsResumedUntilAnsweredOrGivenUpAtTheTimeout) {
  LaterHandler handler;
  HttpServerOptions options;
  options.request_timeout_s = 0.5;
  HttpServer server(options, handler);
  std::thread thread([&] { server.run(nullptr, 2); });
  const std::string host = "Host: 127.0.0.1:" + std::to_string(server.port()) + "\r\n";
  const std::string later = http_exchange(server.port(), "GET /later HTTP/1.1\r\n" + host + "\r\n");
  EXPECT_EQ(http_status(later), 200);
  EXPECT_EQ(http_body(later), "later\n");
  EXPECT_EQ(handler.resumes.load(), 5);

  handler.parts = 1000000;  // never done: the request timeout gives it up
  HttpConnection c(server.port());
  c.send("GET /later HTTP/1.1\r\n" + host + "\r\n");
  // Another client is answered while it is resumed.
  EXPECT_EQ(http_body(http_exchange(server.port(), "GET / HTTP/1.1\r\n" + host + "\r\n")), "now\n");
  EXPECT_EQ(http_status(c.read_all(10.0)), 503);
  server.stop();
  thread.join();
  EXPECT_EQ(handler.abandoned.load(), 1);
  EXPECT_TRUE(handler.remaining.empty());
}
