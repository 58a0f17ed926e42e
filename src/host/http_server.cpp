#include "piezoshift/host/http_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::host {

namespace {

constexpr std::size_t kReadChunkBytes = 16 * 1024;

void close_fd(int& fd) noexcept {
  if (fd >= 0)
    ::close(fd);
  fd = -1;
}

bool would_block(int err) {
  return err == EAGAIN || err == EWOULDBLOCK;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t'))
    s.remove_suffix(1);
  return s;
}

// %XX and '+' decoding of a query component; false on a malformed escape.
bool url_decode(std::string_view in, std::string& out) {
  out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (in[i] == '+') {
      out += ' ';
    } else if (in[i] == '%') {
      unsigned value = 0;
      if (i + 2 >= in.size())
        return false;
      const auto r = std::from_chars(in.data() + i + 1, in.data() + i + 3, value, 16);
      if (r.ec != std::errc() || r.ptr != in.data() + i + 3)
        return false;
      out += static_cast<char>(value);
      i += 2;
    } else {
      out += in[i];
    }
  }
  return true;
}

// Compares in time independent of where the strings differ (a token guessed byte by byte).
bool same_secret(std::string_view a, std::string_view b) {
  unsigned diff = a.size() == b.size() ? 0u : 1u;
  for (std::size_t i = 0; i < a.size(); ++i)
    diff |= static_cast<unsigned>(a[i] ^ (i < b.size() ? b[i] : 0));
  return diff == 0;
}

enum class Parse { kIncomplete, kDone, kBad, kHeadersTooLarge, kBodyTooLarge };

Parse parse_request(const std::string& input, const HttpServerOptions& o, HttpRequest& r,
                    std::size_t& consumed) {
  std::size_t end = input.find("\r\n\r\n");
  std::size_t sep = 4;
  if (const std::size_t lf = input.find("\n\n"); lf != std::string::npos && lf < end) {
    end = lf;
    sep = 2;
  }
  if (end == std::string::npos)
    return input.size() > o.max_request_bytes ? Parse::kHeadersTooLarge : Parse::kIncomplete;
  if (end > o.max_request_bytes)
    return Parse::kHeadersTooLarge;

  std::string_view head(input.data(), end);
  std::vector<std::string_view> lines;
  while (!head.empty()) {
    const std::size_t lf = head.find('\n');
    std::string_view line = head.substr(0, lf);
    if (!line.empty() && line.back() == '\r')
      line.remove_suffix(1);
    lines.push_back(line);
    if (lf == std::string_view::npos)
      break;
    head.remove_prefix(lf + 1);
  }
  if (lines.empty())
    return Parse::kBad;
  // Request line: METHOD SP target SP HTTP/1.x
  const std::string_view rl = lines[0];
  const std::size_t s1 = rl.find(' ');
  const std::size_t s2 = rl.rfind(' ');
  if (s1 == std::string_view::npos || s2 == s1)
    return Parse::kBad;
  r.method = std::string(rl.substr(0, s1));
  const std::string_view target = rl.substr(s1 + 1, s2 - s1 - 1);
  const std::string_view version = rl.substr(s2 + 1);
  if (version != "HTTP/1.1" && version != "HTTP/1.0")
    return Parse::kBad;
  if (target.empty() || target.front() != '/')
    return Parse::kBad;
  const std::size_t q = target.find('?');
  r.path = std::string(target.substr(0, q));
  if (q != std::string_view::npos) {
    std::string_view query = target.substr(q + 1);
    while (!query.empty()) {
      const std::size_t amp = query.find('&');
      const std::string_view pair = query.substr(0, amp);
      const std::size_t eq = pair.find('=');
      std::string key, value;
      if (!url_decode(pair.substr(0, eq), key) ||
          !url_decode(eq == std::string_view::npos ? std::string_view{} : pair.substr(eq + 1),
                      value))
        return Parse::kBad;
      r.query[key] = value;
      if (amp == std::string_view::npos)
        break;
      query.remove_prefix(amp + 1);
    }
  }
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::size_t colon = lines[i].find(':');
    if (colon == std::string_view::npos || colon == 0)
      return Parse::kBad;
    r.headers[lower(trim(lines[i].substr(0, colon)))] =
        std::string(trim(lines[i].substr(colon + 1)));
  }
  if (r.headers.count("transfer-encoding") != 0)
    return Parse::kBad;  // no chunked uploads: nothing here needs them
  std::size_t length = 0;
  if (const auto it = r.headers.find("content-length"); it != r.headers.end()) {
    const std::string& v = it->second;
    const auto res = std::from_chars(v.data(), v.data() + v.size(), length);
    if (res.ec != std::errc() || res.ptr != v.data() + v.size())
      return Parse::kBad;
    if (length > o.max_body_bytes)
      return Parse::kBodyTooLarge;
  }
  const std::size_t body_at = end + sep;
  if (input.size() < body_at + length)
    return Parse::kIncomplete;
  r.body = input.substr(body_at, length);
  consumed = body_at + length;
  return Parse::kDone;
}

}  // namespace

std::string HttpRequest::header(const std::string& lower_name) const {
  const auto it = headers.find(lower_name);
  return it == headers.end() ? std::string{} : it->second;
}

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

HttpServer::HttpServer(const HttpServerOptions& options, HttpHandler& handler)
    : options_(options), handler_(handler) {
  const std::string where = fmt::format("{}:{}", options.host, options.port);
  const auto fail = [&](const std::string& what) {
    throw core::InputError(fmt::format("HTTP server on {}: {}", where, what));
  };
  if (options.max_clients < 1 || options.max_request_bytes < 256 || options.max_body_bytes < 1 ||
      !(options.request_timeout_s > 0.0) || options.max_pending_output_bytes < 1)
    fail("invalid limits");
  const Ipv4Host ip = parse_ipv4_host(options.host, "HTTP server", where);
  if (!ip.loopback && options.token.empty())
    fail(
        fmt::format("refuses non-loopback address {} without an access token (--http-token or "
                    "--http-token-file): anyone who reaches the port could move the stage",
                    options.host));
  listener_ = std::make_unique<TcpListener>(ip, options.port, "HTTP server", where);
  for (const std::string& h : {std::string("127.0.0.1"), std::string("localhost"), ip.numeric})
    allowed_hosts_.push_back(fmt::format("{}:{}", h, listener_->port()));
}

HttpServer::~HttpServer() {
  for (Client& c : clients_)
    close_fd(c.fd);
}

void HttpServer::stop() noexcept {
  stop_requested_.store(true);
  listener_->wake();
}

HttpServerStats HttpServer::stats() const {
  constexpr auto r = std::memory_order_relaxed;
  HttpServerStats s;
  s.requests = stats_.requests.load(r);
  s.refused = stats_.refused.load(r);
  s.unauthorised = stats_.unauthorised.load(r);
  s.streams_opened = stats_.streams_opened.load(r);
  s.dropped_slow = stats_.dropped_slow.load(r);
  s.broadcast_bytes = stats_.broadcast_bytes.load(r);
  s.accept_failures = listener_->accept_failures();
  return s;
}

std::size_t HttpServer::stream_count() const noexcept {
  return static_cast<std::size_t>(
      std::count_if(clients_.begin(), clients_.end(), [](const Client& c) { return c.stream; }));
}

void HttpServer::run(const std::atomic<int>* stop_flag, int poll_interval_ms) {
  const auto stopping = [&] {
    return stop_requested_.load() || (stop_flag != nullptr && stop_flag->load() != 0);
  };
  const auto timeout = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(options_.request_timeout_s));
  std::vector<pollfd> fds;
  while (!stopping()) {
    handler_.on_poll(*this);
    fds.clear();
    fds.push_back({listener_->wake_fd(), POLLIN, 0});
    fds.push_back({listener_->poll_fd(), POLLIN, 0});  // -1 while accepting is paused
    for (const Client& c : clients_) {
      short events = c.answered ? 0 : POLLIN;
      if (c.pending() > 0)
        events |= POLLOUT;
      // A stream's peer sends nothing; still watch for its hang-up (POLLIN gives EOF).
      if (c.stream)
        events |= POLLIN;
      fds.push_back({c.fd, events, 0});
    }
    if (::poll(fds.data(), fds.size(), poll_interval_ms) < 0) {
      if (errno == EINTR)
        continue;
      throw std::runtime_error(fmt::format("HTTP server: poll: {}", std::strerror(errno)));
    }
    if (fds[0].revents != 0)
      listener_->drain_wake();
    for (std::size_t i = 0; i + 2 < fds.size(); ++i) {
      Client& c = clients_[i];
      const short revents = fds[i + 2].revents;
      if (revents & POLLNVAL)
        c.close = true;
      if (!c.close && (revents & (POLLIN | POLLHUP | POLLERR)))
        read_from(c);
      if (!c.close && c.pending() > 0)
        flush(c);
    }
    const auto now = Clock::now();
    for (Client& c : clients_) {
      if (c.close || c.stream || now - c.accepted <= timeout)
        continue;
      if (!c.answered) {
        respond(c, HttpResponse::text(408, "request not complete within the timeout"));
        flush(c);
      }
      c.close = true;  // answered but not read by its peer within the timeout: give up the slot
    }
    std::erase_if(clients_, [](Client& c) {
      if (c.close)
        close_fd(c.fd);
      return c.fd < 0;
    });
    if (fds[1].revents & POLLIN)
      accept_clients();
  }
  for (Client& c : clients_)
    close_fd(c.fd);
  clients_.clear();
}

void HttpServer::accept_clients() {
  for (;;) {
    const int fd = listener_->accept_client();
    if (fd < 0)
      return;
    Client c;
    c.fd = fd;
    c.accepted = Clock::now();
    if (clients_.size() >= options_.max_clients) {
      // Best effort: a 503 that fits in the socket buffer, then closed.
      respond(c, HttpResponse::text(503, "too many clients"));
      flush(c);
      ::close(fd);
      continue;
    }
    clients_.push_back(std::move(c));
  }
}

void HttpServer::read_from(Client& c) {
  char buffer[kReadChunkBytes];
  const ssize_t n = ::recv(c.fd, buffer, sizeof buffer, 0);
  if (n > 0) {
    if (c.answered)
      return;  // nothing more is read on an answered connection (a stream's peer is silent)
    c.input.append(buffer, static_cast<std::size_t>(n));
    try_answer(c);
  } else if (n == 0 || (errno != EINTR && !would_block(errno))) {
    c.close = true;  // EOF or reset; the answer in flight, if any, is not wanted any more
  }
}

void HttpServer::try_answer(Client& c) {
  HttpRequest request;
  std::size_t consumed = 0;
  switch (parse_request(c.input, options_, request, consumed)) {
    case Parse::kIncomplete:
      return;
    case Parse::kBad:
      respond(c, HttpResponse::text(400, "malformed HTTP/1.1 request"));
      return;
    case Parse::kHeadersTooLarge:
      respond(c, HttpResponse::text(431, fmt::format("request line and headers exceed {} bytes",
                                                     options_.max_request_bytes)));
      return;
    case Parse::kBodyTooLarge:
      respond(c, HttpResponse::text(
                     413, fmt::format("request body exceeds {} bytes", options_.max_body_bytes)));
      return;
    case Parse::kDone:
      break;
  }
  c.input.clear();
  HttpResponse response;
  try {
    response = answer(request);
  } catch (const std::exception& e) {
    response = HttpResponse::text(500, e.what());
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

void HttpServer::respond(Client& c, const HttpResponse& r) {
  stats_.requests.fetch_add(1, std::memory_order_relaxed);
  if (r.status >= 400)
    stats_.refused.fetch_add(1, std::memory_order_relaxed);
  c.answered = true;
  std::string head = fmt::format(
      "HTTP/1.1 {} {}\r\nContent-Type: {}\r\nCache-Control: no-store\r\n"
      "X-Content-Type-Options: nosniff\r\n",
      r.status, http_reason(r.status), r.stream ? "text/event-stream" : r.content_type);
  if (r.status == 401)
    head += "WWW-Authenticate: Bearer\r\n";
  if (r.stream && r.status == 200) {
    c.stream = true;
    stats_.streams_opened.fetch_add(1, std::memory_order_relaxed);
    head += "Connection: keep-alive\r\n\r\n";
  } else {
    head += fmt::format("Content-Length: {}\r\nConnection: close\r\n\r\n", r.body.size());
  }
  queue(c, head);
  queue(c, r.body);
}

void HttpServer::broadcast(std::string_view bytes) {
  for (Client& c : clients_) {
    if (!c.stream || c.close)
      continue;
    stats_.broadcast_bytes.fetch_add(bytes.size(), std::memory_order_relaxed);
    queue(c, bytes);
    flush(c);
  }
}

void HttpServer::queue(Client& c, std::string_view bytes) {
  if (c.pending() + bytes.size() > options_.max_pending_output_bytes) {
    stats_.dropped_slow.fetch_add(1, std::memory_order_relaxed);
    c.close = true;
    return;
  }
  c.output.append(bytes);
}

void HttpServer::flush(Client& c) {
  while (c.pending() > 0) {
    const ssize_t n = ::send(c.fd, c.output.data() + c.output_sent, c.pending(), MSG_NOSIGNAL);
    if (n > 0) {
      c.output_sent += static_cast<std::size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && would_block(errno)) {
      break;
    } else {
      c.close = true;
      return;
    }
  }
  if (c.pending() == 0) {
    c.output.clear();
    c.output_sent = 0;
    if (c.answered && !c.stream)
      c.close = true;
  } else if (c.output_sent > kReadChunkBytes) {
    c.output.erase(0, c.output_sent);
    c.output_sent = 0;
  }
}

}  // namespace piezoshift::host
