#pragma once
// A small, bounded HTTP/1.1 server on one poll() thread: the dashboard of `piezoshift serve`
// (docs/dashboard.md). It knows the protocol only; what a request means is the HttpHandler's.
//
//   request    one per connection: "METHOD target HTTP/1.x", headers, a body only with
//              Content-Length (no chunked uploads); the answer carries "Connection: close"
//   bounds     max_clients (one more gets 503 and is closed), max_request_bytes for the
//              request line and headers (431), max_body_bytes (413), request_timeout_s for a
//              request to arrive whole (408) and for its answer to be taken (else closed),
//              max_pending_output_bytes per client (a reader that slow is dropped); malformed
//              requests get 400, other methods 405
//   access     with a token, every request must carry "Authorization: Bearer TOKEN" or
//              "?token=TOKEN" (EventSource cannot set headers), else 401. A non-loopback bind
//              is refused without a token. Without a token the Host header must name this
//              server (a page of another site reaching 127.0.0.1 through DNS rebinding gets 403);
//              a POST must be application/json (a cross-site form cannot send that) from no Origin
//              or this server's own (403)
//   streams    a handler may answer with a stream (Server-Sent Events): the connection stays
//              open and receives every broadcast() until it closes or reads too slowly. Streams
//              take at most max_clients - reserved_for_requests slots (at least one), so
//              ordinary requests always find a slot; one more stream gets 503
//   later      a handler may answer HttpResponse::later() and give the response in parts: the
//              server calls resume() once a round (serving every other client in between) until
//              it returns one, or abandon() when the connection ends first (reset, or the request
//              timeout, which answers 503)
//   room       with max_clients connected, a new connection takes the place of the one whose
//              request has been incomplete longest, if for evict_incomplete_when_full_s since its
//              first byte (a client trickling its headers), else of the one silent longest (a
//              stream: the one opened first) if silent for evict_idle_when_full_s
//              (poll_server.hpp); otherwise it gets 503
//   memory     per client: max_request_bytes + max_body_bytes of request, max_pending_output_bytes
//              of queued answer and events (the handler's own state aside)
//   poll       it runs on the shared poll server (poll_server.hpp), as the GCS LineServer does: one
//              thread, the accept back-off, at most kReadChunkBytes read from a client per round,
//              bounded send queues with slow-reader eviction
// Why not a library: Debian 12's cpp-httplib (0.11) serves each connection on a pool thread with
// an unbounded queue, so every open event stream holds a thread and the bounds above are not
// expressible. Not real-time code.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/host/http_request.hpp"
#include "piezoshift/host/poll_server.hpp"

namespace piezoshift::host {

struct HttpServerOptions {
  std::string host = "127.0.0.1";  //!< numeric IPv4 address, or localhost
  std::uint16_t port = 0;          //!< 0: the kernel picks a free one, see HttpServer::port()
  //! Required on every request when set; required to bind outside 127.0.0.0/8.
  std::string token;
  std::size_t max_clients = 16;          //!< connections at once
  std::size_t max_request_bytes = 8192;  //!< request line + headers
  std::size_t max_body_bytes = 16384;    //!< POST bodies
  double request_timeout_s = 10.0;       //!< for a request to arrive and its answer to be taken
  std::size_t max_pending_output_bytes = std::size_t{4} << 20;  //!< per client
  //! Slots event streams cannot take (they get 503), so that requests always find one.
  std::size_t reserved_for_requests = 2;
  //! A full table's newcomer takes the place of the client silent longest if silent this long
  //! [s] (PollServerLimits::evict_idle_when_full_s); 0: always, +inf: never.
  double evict_idle_when_full_s = 1.0;
  //! Before that: the client whose request (head and body) has been incomplete longest, if its
  //! first byte came at least this long ago [s] (evict_incomplete_when_full_s); +inf: never.
  double evict_incomplete_when_full_s = 2.0;
};

struct HttpResponse {
  int status = 200;
  std::string content_type = "text/plain; charset=utf-8";
  std::string body;
  //! Keep the connection open as a text/event-stream that receives HttpServer::broadcast();
  //! body is sent first (e.g. a first event).
  bool stream = false;
  //! Not answered yet: the server calls HttpHandler::resume() every round until it answers.
  bool later = false;

  static HttpResponse text(int status, std::string body);
  static HttpResponse json(int status, std::string body);
  //! See `later` above.
  static HttpResponse deferred();
};

//! "OK", "Not Found", ... for the codes this server uses.
const char* http_reason(int status) noexcept;

class HttpServer;

class HttpHandler {
 public:
  virtual ~HttpHandler() = default;
  //! A complete, authorised request. Called from the run() thread.
  virtual HttpResponse on_request(const HttpRequest& request) = 0;
  //! Every turn of run(), at least every poll interval: where a handler broadcasts.
  virtual void on_poll(HttpServer&) {}
  //! For a request answered HttpResponse::deferred(): called once per round (poll() does not
  //! sleep meanwhile) with the request's HttpRequest::client until it returns a response that is
  //! not deferred; it should do a bounded part of the work each time.
  virtual HttpResponse resume(std::uint64_t client);
  //! The connection of a deferred request ended (closed, timed out) before its response.
  virtual void abandon(std::uint64_t) {}
};

struct HttpServerStats {
  std::uint64_t requests = 0;             //!< answered, any status
  std::uint64_t refused = 0;              //!< 4xx/5xx answers, 401 included
  std::uint64_t unauthorised = 0;         //!< 401
  std::uint64_t streams_opened = 0;       //!< event streams started
  std::uint64_t dropped_slow = 0;         //!< readers beyond max_pending_output_bytes
  std::uint64_t broadcast_bytes = 0;      //!< bytes queued by broadcast(), all streams
  std::uint64_t refused_max_clients = 0;  //!< 503 and closed: max_clients already connected
  std::uint64_t refused_streams = 0;      //!< 503: the streams' share of the slots was taken
  std::uint64_t evicted_for_room = 0;     //!< silent longest when a newcomer found the table full
  std::uint64_t bytes_in = 0;             //!< received from all clients
  std::uint64_t bytes_out = 0;            //!< sent (taken by the kernel) to all clients
  //! accept() failed for lack of descriptors or memory; each pauses accepting for 100 ms
  std::uint64_t accept_failures = 0;
};

class HttpServer : private PollProtocol {
 public:
  //! Bytes read from one client per round at most (PollServerLimits::read_budget_bytes).
  static constexpr std::size_t kReadChunkBytes = 16 * 1024;

  //! Binds and listens. Throws core::InputError naming host:port for a bad address, a non-loopback
  //! one without a token, bad limits or a failed bind.
  HttpServer(const HttpServerOptions& options, HttpHandler& handler);
  ~HttpServer() override;
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  std::uint16_t port() const noexcept { return core_->port(); }
  //! Serves until stop() or *stop_flag != 0, then closes every connection.
  void run(const std::atomic<int>* stop_flag = nullptr, int poll_interval_ms = 5);
  //! Thread-safe and async-signal-safe.
  void stop() noexcept;

  //! Queues bytes for every open stream (run() thread only, i.e. from HttpHandler::on_poll).
  void broadcast(std::string_view bytes);
  //! Open event streams (run() thread only).
  std::size_t stream_count() const noexcept;
  HttpServerStats stats() const;

 private:
  struct Client;
  //! The connection as make_client() made it.
  static Client& client(PollClient& c) noexcept;
  static const Client& client(const PollClient& c) noexcept;
  std::unique_ptr<PollClient> make_client() override;
  std::string refusal() override;
  //! Broadcasts (the handler's on_poll) and the request timeout.
  void on_round() override;
  bool wants_input(const PollClient& client) const override;
  bool has_work(const PollClient& client) const override;
  std::optional<std::chrono::steady_clock::time_point> incomplete_since(
      const PollClient& client) const override;
  void on_input(PollClient& client, std::string_view bytes) override;
  void on_end_of_input(PollClient& client) override;
  //! Resumes a deferred request.
  void serve(PollClient& client) override;
  void on_disconnect(PollClient& client) override;
  //! Parses the client's input when a whole request is there; answers it (or an error).
  void try_answer(Client& c);
  HttpResponse answer(const HttpRequest& request);
  //! Counts the answer; the status line, headers and body.
  std::string format(const HttpResponse& response);
  void respond(Client& c, const HttpResponse& response);

  HttpServerOptions options_;
  HttpHandler& handler_;
  std::vector<std::string> allowed_hosts_;  // Host header values naming this server
  std::unique_ptr<PollServer> core_;
  struct AtomicStats {
    std::atomic<std::uint64_t> requests{0}, refused{0}, unauthorised{0}, streams_opened{0},
        broadcast_bytes{0}, refused_streams{0};
  } stats_;
};

}  // namespace piezoshift::host
