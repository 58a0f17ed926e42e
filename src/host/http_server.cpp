#include "piezoshift/host/http_server.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::host {

namespace {

// Compares in time independent of where the strings differ (a token guessed byte by byte).
bool same_secret(std::string_view a, std::string_view b) {
  unsigned diff = a.size() == b.size() ? 0u : 1u;
  for (std::size_t i = 0; i < a.size(); ++i)
    diff |= static_cast<unsigned>(a[i] ^ (i < b.size() ? b[i] : 0));
  return diff == 0;
}

}  // namespace

HttpResponse HttpResponse::text(int status, std::string body) {
  HttpResponse r;
  r.status = status;
  r.body = std::move(body);
  if (!r.body.empty() && r.body.back() != '\n')
    r.body += '\n';
  return r;
}

HttpResponse HttpResponse::json(int status, std::string body) {
  HttpResponse r;
  r.status = status;
  r.content_type = "application/json";
  r.body = std::move(body);
  return r;
}

HttpResponse HttpResponse::deferred() {
  HttpResponse r;
  r.later = true;
  return r;
}

HttpResponse HttpHandler::resume(std::uint64_t) {
  return HttpResponse::text(500, "this handler does not answer in parts");
}

const char* http_reason(int status) noexcept {
  switch (status) {
    case 200:
      return "OK";
    case 204:
      return "No Content";
    case 400:
      return "Bad Request";
    case 401:
      return "Unauthorized";
    case 403:
      return "Forbidden";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    case 408:
      return "Request Timeout";
    case 409:
      return "Conflict";
    case 413:
      return "Payload Too Large";
    case 415:
      return "Unsupported Media Type";
    case 422:
      return "Unprocessable Content";
    case 431:
      return "Request Header Fields Too Large";
    case 500:
      return "Internal Server Error";
    case 503:
      return "Service Unavailable";
    default:
      return "Unknown";
  }
}

struct HttpServer::Client : PollClient {
  std::string input;
  std::chrono::steady_clock::time_point accepted = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point first_byte;  // of the request (input not empty)
  bool answered = false;  // a response is queued: closed once it is sent (unless a stream)
  bool stream = false;
  bool deferred = false;  // the handler answers in parts (resume())
};

HttpServer::Client& HttpServer::client(PollClient& c) noexcept {
  return static_cast<Client&>(c);
}

const HttpServer::Client& HttpServer::client(const PollClient& c) noexcept {
  return static_cast<const Client&>(c);
}

HttpServer::HttpServer(const HttpServerOptions& options, HttpHandler& handler)
    : options_(options), handler_(handler) {
  const std::string where = fmt::format("{}:{}", options.host, options.port);
  const auto fail = [&](const std::string& what) {
    throw core::InputError(fmt::format("HTTP server on {}: {}", where, what));
  };
  if (options.max_clients < 1 || options.max_request_bytes < 256 || options.max_body_bytes < 1 ||
      !(options.request_timeout_s > 0.0) || options.max_pending_output_bytes < 1 ||
      !(options.evict_idle_when_full_s >= 0.0) || !(options.evict_incomplete_when_full_s >= 0.0))
    fail("invalid limits");
  const Ipv4Host ip = parse_ipv4_host(options.host, "HTTP server", where);
  if (!ip.loopback && options.token.empty())
    fail(
        fmt::format("refuses non-loopback address {} without an access token (--http-token or "
                    "--http-token-file): anyone who reaches the port could move the stage",
                    options.host));
  PollServerLimits core;
  core.max_clients = options.max_clients;
  core.read_budget_bytes = kReadChunkBytes;
  core.max_pending_output_bytes = options.max_pending_output_bytes;
  // A stream's peer sends nothing and may wait long between events; the request timeout in
  // on_round() bounds every other connection.
  core.send_timeout_s = std::numeric_limits<double>::infinity();
  core.idle_timeout_s = std::numeric_limits<double>::infinity();
  core.evict_idle_when_full_s = options.evict_idle_when_full_s;
  core.evict_incomplete_when_full_s = options.evict_incomplete_when_full_s;
  core_ = std::make_unique<PollServer>(ip, options.port, "HTTP server", where, core,
                                       static_cast<PollProtocol&>(*this));
  for (const std::string& h : {std::string("127.0.0.1"), std::string("localhost"), ip.numeric})
    allowed_hosts_.push_back(fmt::format("{}:{}", h, core_->port()));
}

HttpServer::~HttpServer() = default;

void HttpServer::run(const std::atomic<int>* stop_flag, int poll_interval_ms) {
  core_->run(stop_flag, poll_interval_ms);
}

void HttpServer::stop() noexcept {
  core_->stop();
}

HttpServerStats HttpServer::stats() const {
  constexpr auto r = std::memory_order_relaxed;
  const PollServerStats c = core_->stats();
  HttpServerStats s;
  s.requests = stats_.requests.load(r);
  s.refused = stats_.refused.load(r);
  s.unauthorised = stats_.unauthorised.load(r);
  s.streams_opened = stats_.streams_opened.load(r);
  s.dropped_slow = c.evicted_slow;
  s.broadcast_bytes = stats_.broadcast_bytes.load(r);
  s.accept_failures = c.accept_failures;
  s.refused_max_clients = c.refused_max_clients;
  s.refused_streams = stats_.refused_streams.load(r);
  s.evicted_for_room = c.evicted_for_room;
  s.bytes_in = c.bytes_in;
  s.bytes_out = c.bytes_out;
  return s;
}

std::size_t HttpServer::stream_count() const noexcept {
  std::size_t n = 0;
  core_->for_each_client([&](PollClient& c) { n += client(c).stream ? 1 : 0; });
  return n;
}

std::unique_ptr<PollClient> HttpServer::make_client() {
  return std::make_unique<Client>();
}

std::string HttpServer::refusal() {
  return format(HttpResponse::text(503, "too many clients"));
}

void HttpServer::on_round() {
  handler_.on_poll(*this);
  const auto timeout = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(options_.request_timeout_s));
  const auto now = std::chrono::steady_clock::now();
  core_->for_each_client([&](PollClient& polled) {
    Client& c = client(polled);
    if (c.closing() || c.stream || now - c.accepted <= timeout)
      return;
    if (c.deferred) {  // its handler took too long: given up, and the peer told so
      c.deferred = false;
      handler_.abandon(c.id());
      respond(c, HttpResponse::text(503, "the answer was not ready within the request timeout"));
      core_->flush(c);
    } else if (!c.answered) {
      respond(c, HttpResponse::text(408, "request not complete within the timeout"));
      core_->flush(c);
    }
    core_->close(c);  // answered but not read by its peer within the timeout: give up the slot
  });
}

bool HttpServer::wants_input(const PollClient& polled) const {
  // A stream's peer sends nothing; still read, for its hang-up (EOF).
  const Client& c = HttpServer::client(polled);
  return !c.answered || c.stream || c.deferred;  // a deferred one: for a reset
}

void HttpServer::on_end_of_input(PollClient& polled) {
  // A peer may shut down its sending side once its request is sent: its deferred answer is still
  // made and sent (a peer that has gone fails the send, and the connection is closed then).
  if (!client(polled).deferred)
    PollProtocol::on_end_of_input(polled);
}

std::optional<std::chrono::steady_clock::time_point> HttpServer::incomplete_since(
    const PollClient& polled) const {
  const Client& c = client(polled);
  if (c.answered || c.input.empty())
    return std::nullopt;
  return c.first_byte;
}

bool HttpServer::has_work(const PollClient& polled) const {
  return HttpServer::client(polled).deferred;
}

void HttpServer::serve(PollClient& polled) {
  Client& c = client(polled);
  if (!c.deferred)
    return;
  HttpResponse response;
  try {
    response = handler_.resume(c.id());
  } catch (const std::exception& e) {
    response = HttpResponse::text(500, e.what());
  }
  if (response.later)
    return;
  c.deferred = false;
  respond(c, response);
}

void HttpServer::on_disconnect(PollClient& polled) {
  Client& c = client(polled);
  if (c.deferred) {
    c.deferred = false;
    handler_.abandon(c.id());
  }
}

void HttpServer::on_input(PollClient& polled, std::string_view bytes) {
  Client& c = client(polled);
  if (c.answered)
    return;  // nothing more is read on an answered connection (a stream's peer is silent)
  if (c.input.empty())
    c.first_byte = std::chrono::steady_clock::now();
  c.input.append(bytes);
  try_answer(c);
}

void HttpServer::try_answer(Client& c) {
  HttpRequest request;
  switch (
      parse_http_request(c.input, options_.max_request_bytes, options_.max_body_bytes, request)) {
    case HttpParse::kIncomplete:
      return;
    case HttpParse::kBad:
      respond(c, HttpResponse::text(400, "malformed HTTP/1.1 request"));
      return;
    case HttpParse::kHeadersTooLarge:
      respond(c, HttpResponse::text(431, fmt::format("request line and headers exceed {} bytes",
                                                     options_.max_request_bytes)));
      return;
    case HttpParse::kBodyTooLarge:
      respond(c, HttpResponse::text(
                     413, fmt::format("request body exceeds {} bytes", options_.max_body_bytes)));
      return;
    case HttpParse::kDone:
      break;
  }
  c.input.clear();
  request.client = c.id();
  HttpResponse response;
  try {
    response = answer(request);
  } catch (const std::exception& e) {
    response = HttpResponse::text(500, e.what());
  }
  if (response.later) {
    c.answered = true;  // nothing more is read; resume() answers it
    c.deferred = true;
    return;
  }
  respond(c, response);
}

HttpResponse HttpServer::answer(const HttpRequest& request) {
  if (!options_.token.empty()) {
    const std::string auth = request.header("authorization");
    const auto q = request.query.find("token");
    const bool ok =
        (auth.rfind("Bearer ", 0) == 0 && same_secret(auth.substr(7), options_.token)) ||
        (q != request.query.end() && same_secret(q->second, options_.token));
    if (!ok) {
      stats_.unauthorised.fetch_add(1, std::memory_order_relaxed);
      return HttpResponse::text(
          401, "this server needs its access token: 'Authorization: Bearer TOKEN' or ?token=");
    }
  } else {
    const std::string host = request.header("host");
    if (std::find(allowed_hosts_.begin(), allowed_hosts_.end(), host) == allowed_hosts_.end())
      return HttpResponse::text(403, fmt::format("Host '{}' does not name this server", host));
  }
  if (request.method == "POST") {
    if (request.header("content-type").rfind("application/json", 0) != 0)
      return HttpResponse::text(415, "POST bodies must be application/json");
    const std::string origin = request.header("origin");
    if (!origin.empty() && origin != "http://" + request.header("host"))
      return HttpResponse::text(403, fmt::format("cross-origin POST from '{}' refused", origin));
  } else if (request.method != "GET") {
    return HttpResponse::text(405, fmt::format("method {} not allowed", request.method));
  }
  return handler_.on_request(request);
}

std::string HttpServer::format(const HttpResponse& r) {
  stats_.requests.fetch_add(1, std::memory_order_relaxed);
  if (r.status >= 400)
    stats_.refused.fetch_add(1, std::memory_order_relaxed);
  std::string head = fmt::format(
      "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nCache-Control: no-store\r\n"
      "X-Content-Type-Options: nosniff\r\n",
      r.status, http_reason(r.status), r.stream ? "text/event-stream" : r.content_type);
  if (r.status == 401)
    head += "WWW-Authenticate: Bearer\r\n";
  if (r.stream && r.status == 200)
    head += "Connection: keep-alive\r\n\r\n";
  else
    head += fmt::format("Content-Length: {}\r\nConnection: close\r\n\r\n", r.body.size());
  return head + r.body;
}

void HttpServer::respond(Client& c, const HttpResponse& response) {
  const std::size_t max_streams = options_.max_clients > options_.reserved_for_requests
                                      ? options_.max_clients - options_.reserved_for_requests
                                      : 1;
  if (response.stream && response.status == 200 && stream_count() >= max_streams) {
    stats_.refused_streams.fetch_add(1, std::memory_order_relaxed);
    respond(c, HttpResponse::text(503, fmt::format("too many event streams (at most {}; the "
                                                   "other slots are kept for requests)",
                                                   max_streams)));
    return;
  }
  const HttpResponse& r = response;
  c.answered = true;
  core_->queue(c, format(r));
  if (r.stream && r.status == 200) {
    c.stream = true;
    stats_.streams_opened.fetch_add(1, std::memory_order_relaxed);
  } else {
    core_->finish(c);  // Connection: close, once the answer is sent
  }
}

void HttpServer::broadcast(std::string_view bytes) {
  core_->for_each_client([&](PollClient& polled) {
    Client& c = client(polled);
    if (!c.stream || c.closing())
      return;
    stats_.broadcast_bytes.fetch_add(bytes.size(), std::memory_order_relaxed);
    core_->queue(c, bytes);
    if (!c.closing())
      core_->flush(c);
  });
}

}  // namespace piezoshift::host
