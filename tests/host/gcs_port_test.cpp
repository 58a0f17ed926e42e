// The GCS port serves GCS alone, and the GCS client takes bounded answers, over loopback: a
// connection whose first line is HTTP's is closed before any of it runs (host/http_line.hpp),
// and an answer beyond DataRecorder::kMaxAnswerBytes is refused by the client.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "piezoshift/host/gcs_client.hpp"
#include "piezoshift/host/http_line.hpp"
#include "piezoshift/host/line_server.hpp"

namespace piezoshift::host {
namespace {

// ECHO x -> "x\n"; BIG n -> n bytes (n-1 'x' and LF); MULTI n -> n lines in GCS framing; other
// -> "UNKNOWN <length>\n". Keeps every line it was handed.
class TestHandler final : public LineHandler {
 public:
  std::string on_line(ClientId, std::string_view line) override {
    {
      const std::lock_guard lock(mutex_);
      lines_.emplace_back(line);
    }
    if (line.starts_with("ECHO "))
      return std::string(line.substr(5)) + "\n";
    if (line.starts_with("BIG "))
      return std::string(std::stoul(std::string(line.substr(4))) - 1, 'x') + "\n";
    if (line.starts_with("MULTI ")) {
      const int n = std::stoi(std::string(line.substr(6)));
      std::string answer;
      for (int i = 1; i <= n; ++i)
        answer += "line " + std::to_string(i) + (i < n ? " \n" : "\n");
      return answer;
    }
    return "UNKNOWN " + std::to_string(line.size()) + "\n";
  }
  std::vector<std::string> lines() {
    const std::lock_guard lock(mutex_);
    return lines_;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

// A server on an ephemeral loopback port, on its own thread until destruction.
class ServerThread {
 public:
  explicit ServerThread(LineHandler& handler)
      : server_(ListenAddress{"127.0.0.1", 0, false}, LineServerLimits{}, handler),
        thread_([this] { server_.run(); }) {}
  ~ServerThread() {
    server_.stop();
    thread_.join();
  }
  ServerThread(const ServerThread&) = delete;
  ServerThread& operator=(const ServerThread&) = delete;
  LineServer& server() { return server_; }
  std::uint16_t port() const { return server_.port(); }
  std::unique_ptr<GcsClient> connect() {
    return std::make_unique<GcsClient>("127.0.0.1", server_.port());
  }

 private:
  LineServer server_;
  std::thread thread_;
};

// `curl -X POST --data-binary $'SVO Z 1 U 1 V 1\nMOV Z 10\n' http://127.0.0.1:GCSPORT/`
// (or a browser's no-cors fetch) had its body run a line at a time. A connection whose first
// line is HTTP's is closed before anything of it is handled.
TEST(LineServerInput, AnHttpRequestIsClosedBeforeAnyOfItRuns) {
  TestHandler handler;
  ServerThread server(handler);
  const std::string body = "SVO Z 1 U 1 V 1\nMOV Z 10\n";
  const std::vector<std::string> requests{
      "POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: " + std::to_string(body.size()) +
          "\r\n\r\n" + body,
      "GET /?x=1 HTTP/1.0\n\n",
      "Host: 127.0.0.1:50000\r\nECHO a\n",  // a header line first
      "user-agent: curl/7.88\nECHO a\n"};
  for (const std::string& r : requests) {
    auto client = server.connect();
    client->send_raw(r);
    EXPECT_TRUE(client->wait_closed(5.0)) << r;
  }
  EXPECT_TRUE(handler.lines().empty());
  EXPECT_EQ(server.server().stats().refused_http, requests.size());
  // GCS lines are never taken for HTTP; only the first line is judged.
  auto gcs = server.connect();
  EXPECT_EQ(gcs->query("ECHO a: b HTTP/1.1"), "a: b HTTP/1.1\n");
  EXPECT_EQ(gcs->query("Host: x"), "UNKNOWN 7\n");
  EXPECT_EQ(server.server().stats().refused_http, requests.size());
}

TEST(HttpLine, RequestAndHeaderLinesAreHttpGcsLinesAreNot) {
  for (const char* http :
       {"POST / HTTP/1.1", "GET /api/stream?token=x HTTP/1.1", "OPTIONS * HTTP/2", "PRI * HTTP/2.0",
        "Host: 127.0.0.1:50000", "Content-Type: text/plain",
        "X-Custom-Header:", "user-agent: curl/7.88.1"})
    EXPECT_TRUE(looks_like_http(http)) << http;
  for (const char* gcs :
       {"*IDN?", "MOV Z 10", "SVO Z 1 U 1 V 1", "POS?", "SPA Z 0x07000000 1", "DRR? 1 100 1",
        "WGO 1 1", "ERR?", "", "MOV Z 1 HTTP/1.1x", "GET / HTTP/1.1 more", "a b: c", ":x"})
    EXPECT_FALSE(looks_like_http(gcs)) << gcs;
}

// `piezoshift gcs` against a server that never ends its answer buffered 8.6 GB in
// 40 s. An answer is read up to max_answer_bytes (by default the largest DRR?) and no further.
TEST(GcsClient, AnAnswerBeyondItsBoundIsRefusedNamingIt) {
  EXPECT_EQ(DataRecorder::kMaxAnswerBytes, 1180672u);
  TestHandler handler;
  ServerThread server(handler);
  GcsClient client("127.0.0.1", server.port(), 5.0, 1000);
  EXPECT_EQ(client.query("BIG 1000").size(), 1000u);  // at the bound: taken
  try {
    client.query("MULTI 200");  // 1 891 bytes in 200 lines
    FAIL() << "an answer beyond the bound was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds 1000 bytes"), std::string::npos) << e.what();
  }
  GcsClient other("127.0.0.1", server.port(), 5.0, 1000);
  EXPECT_THROW(other.query("BIG 1001"), std::runtime_error);  // one byte more, in one piece

  // A server that sends without end: refused once the default bound is crossed.
  const int listener = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(listener, reinterpret_cast<sockaddr*>(&sa), sizeof sa), 0);
  ASSERT_EQ(::listen(listener, 1), 0);
  socklen_t len = sizeof sa;
  ::getsockname(listener, reinterpret_cast<sockaddr*>(&sa), &len);
  std::thread endless([listener] {
    const int fd = ::accept(listener, nullptr, nullptr);
    const std::string chunk(65536, 'x');
    while (fd >= 0 && ::send(fd, chunk.data(), chunk.size(), MSG_NOSIGNAL) > 0) {
    }
    if (fd >= 0)
      ::close(fd);
  });
  {
    GcsClient victim("127.0.0.1", ntohs(sa.sin_port));
    try {
      victim.query("POS?");
      ADD_FAILURE() << "an endless answer was taken";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("exceeds 1180672 bytes"), std::string::npos) << e.what();
    }
  }  // closed: the sender's send() fails
  endless.join();
  ::close(listener);
}

}  // namespace
}  // namespace piezoshift::host
