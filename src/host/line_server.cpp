#include "piezoshift/host/line_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::host {

namespace {

//! Bytes taken from one client per turn: a client that floods cannot starve the others.
constexpr std::size_t kReadChunkBytes = 64 * 1024;

void close_fd(int& fd) noexcept {
  if (fd >= 0)
    ::close(fd);
  fd = -1;
}

bool would_block(int err) {
  return err == EAGAIN || err == EWOULDBLOCK;
}

void check_limits(const LineServerLimits& limits, const std::string& where) {
  const auto fail = [&](const char* what) {
    throw core::InputError(fmt::format("TCP server on {}: {}", where, what));
  };
  if (limits.max_clients < 1)
    fail("max_clients must be at least 1");
  if (limits.max_line_bytes < 1)
    fail("max_line_bytes must be at least 1");
  if (limits.max_pending_output_bytes < 1)
    fail("max_pending_output_bytes must be at least 1");
  if (limits.output_high_water_bytes < 1)
    fail("output_high_water_bytes must be at least 1");
  if (!(limits.idle_timeout_s > 0.0))  // also rejects NaN
    fail("idle_timeout_s must be > 0 (+inf: no timeout)");
  if (!(limits.send_timeout_s > 0.0))
    fail("send_timeout_s must be > 0 (+inf: no timeout)");
}

}  // namespace

LineServer::LineServer(const ListenAddress& address, const LineServerLimits& limits,
                       LineHandler& handler)
    : limits_(limits), handler_(handler), read_buffer_(kReadChunkBytes) {
  const std::string where = fmt::format("{}:{}", address.host, address.port);
  check_limits(limits, where);

  const Ipv4Host ip = parse_ipv4_host(address.host, "TCP server", where);
  if (!ip.loopback && !address.allow_remote)
    throw core::InputError(fmt::format(
        "TCP server on {} refuses non-loopback address {} without --allow-remote (GCS has no "
        "authentication: anyone who reaches the port moves the stage)",
        where, address.host));
  listener_ = std::make_unique<TcpListener>(ip, address.port, "TCP server", where);
}

LineServer::~LineServer() {
  for (Client& c : clients_)
    close_fd(c.fd);
}

void LineServer::stop() noexcept {
  stop_requested_.store(true);
  listener_->wake();
}

LineServerStats LineServer::stats() const {
  constexpr auto r = std::memory_order_relaxed;
  LineServerStats s;
  s.accepted = stats_.accepted.load(r);
  s.refused_max_clients = stats_.refused_max_clients.load(r);
  s.disconnected_slow = stats_.disconnected_slow.load(r);
  s.disconnected_idle = stats_.disconnected_idle.load(r);
  s.overlong_lines = stats_.overlong_lines.load(r);
  s.bytes_in = stats_.bytes_in.load(r);
  s.bytes_out = stats_.bytes_out.load(r);
  s.accept_failures = listener_->accept_failures();
  return s;
}

void LineServer::run(const std::atomic<int>* stop_flag, int poll_interval_ms) {
  if (poll_interval_ms < 1)
    throw std::invalid_argument("LineServer::run: poll_interval_ms must be at least 1");
  const auto stopping = [&] {
    return stop_requested_.load() || (stop_flag != nullptr && stop_flag->load() != 0);
  };
  const auto limit = [](double s) {
    return std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(std::isfinite(s) ? s : 0.0));
  };
  const bool idle_limited = std::isfinite(limits_.idle_timeout_s);
  const auto idle_limit = limit(limits_.idle_timeout_s);
  const bool send_limited = std::isfinite(limits_.send_timeout_s);
  const auto send_limit = limit(limits_.send_timeout_s);

  std::vector<pollfd> fds;
  try {
    while (!stopping()) {
      handler_.on_poll();

      // [0] wake-up, [1] listener, [2 + i] clients_[i] (clients accepted later in this turn are
      // polled from the next turn on).
      fds.clear();
      fds.push_back({listener_->wake_fd(), POLLIN, 0});
      fds.push_back({listener_->poll_fd(), POLLIN, 0});  // -1 while accepting is paused
      bool work_left = false;  // lines received but beyond last turn's budget: do not sleep
      for (const Client& c : clients_) {
        short events = wants_input(c) ? POLLIN : 0;
        if (c.pending() > 0)
          events |= POLLOUT;
        fds.push_back({c.fd, events, 0});
        work_left = work_left || (!c.unread.empty() && !throttled(c));
      }
      if (::poll(fds.data(), fds.size(), work_left ? 0 : poll_interval_ms) < 0) {
        if (errno == EINTR)
          continue;
        throw std::runtime_error(fmt::format("TCP server: poll: {}", std::strerror(errno)));
      }

      if (fds[0].revents != 0)
        listener_->drain_wake();
      for (std::size_t i = 0; i + 2 < fds.size(); ++i) {
        Client& c = clients_[i];
        const short revents = fds[i + 2].revents;
        if (revents & POLLNVAL) {
          c.close = Client::Close::kNow;
          continue;
        }
        // POLLHUP/POLLERR: recv() or send() reports what happened.
        if (wants_input(c) && (revents & (POLLIN | POLLHUP | POLLERR)))
          read_from(c);
        if (c.close == Client::Close::kNo && !c.unread.empty() && !throttled(c))
          serve_lines(c);
        if (c.close == Client::Close::kNo && c.pending() > 0)
          flush(c);
      }

      const auto now = Clock::now();
      for (Client& c : clients_) {
        if (c.close != Client::Close::kNo)
          continue;
        // A throttled client's input waits unread by our choice: the send timeout judges it.
        if (idle_limited && !throttled(c) && now - c.last_input > idle_limit)
          c.close = Client::Close::kIdle;
        else if (send_limited && c.pending() > 0 && now - c.last_output > send_limit)
          c.close = Client::Close::kSlow;
      }
      close_marked_clients();
      // Accept after closing, so that a slot freed in this turn is available at once.
      if (fds[1].revents & POLLIN)
        accept_clients();
    }
  } catch (...) {
    close_all_clients();
    throw;
  }
  close_all_clients();
}

void LineServer::accept_clients() {
  for (;;) {
    const int fd = listener_->accept_client();
    if (fd < 0)
      return;
    if (clients_.size() >= limits_.max_clients) {
      // Accept and close rather than leave it in the backlog: the peer learns at once (EOF).
      stats_.refused_max_clients.fetch_add(1, std::memory_order_relaxed);
      ::close(fd);
      continue;
    }
    Client c;
    c.fd = fd;
    c.id = next_id_++;
    c.last_input = Clock::now();
    clients_.push_back(std::move(c));
    client_count_.store(clients_.size());
    stats_.accepted.fetch_add(1, std::memory_order_relaxed);
    handler_.on_connect(clients_.back().id);
  }
}

bool LineServer::throttled(const Client& c) const {
  return c.pending() >= limits_.output_high_water_bytes;
}

bool LineServer::wants_input(const Client& c) const {
  return !c.input_ended && c.unread.empty() && !throttled(c);
}

void LineServer::read_from(Client& c) {
  char* const buffer = read_buffer_.data();
  const ssize_t n = ::recv(c.fd, buffer, read_buffer_.size(), 0);
  if (n > 0) {
    stats_.bytes_in.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
    c.last_input = Clock::now();
    c.unread.assign(buffer, static_cast<std::size_t>(n));
  } else if (n == 0) {
    // EOF: the peer may have only shut down its sending side (`printf '*IDN?\n' | nc -N ...`),
    // so its lines already received are handled and its answers still sent; a partial last line
    // without LF is dropped.
    c.input_ended = true;
    close_if_done(c);
  } else if (errno != EINTR && !would_block(errno)) {
    c.close = Client::Close::kNow;  // ECONNRESET and the like
  }
}

void LineServer::close_if_done(Client& c) {
  if (c.input_ended && c.unread.empty() && c.pending() == 0 && c.close == Client::Close::kNo)
    c.close = Client::Close::kNow;
}

void LineServer::serve_lines(Client& c) {
  std::string_view data = c.unread;
  std::size_t handled = 0;
  while (!data.empty() && c.close == Client::Close::kNo && handled < kLinesPerTurn &&
         !throttled(c)) {
    const std::size_t lf = data.find('\n');
    if (c.discarding) {  // the rest of an overlong line, already reported
      if (lf == std::string_view::npos) {
        data = {};
        break;
      }
      c.discarding = false;
      data.remove_prefix(lf + 1);
      continue;
    }
    ++handled;
    // A single-character command (GCS: #5, #7, ... sent as the control byte alone, no LF) is
    // recognised where a line would start; inside a line the byte belongs to the line.
    if (c.input.empty() && handler_.is_immediate(data.front())) {
      queue(c, handler_.on_immediate(c.id, data.front()));
      data.remove_prefix(1);
      continue;
    }
    if (lf == std::string_view::npos) {
      c.input.append(data);
      data = {};
      // One byte of slack: the last byte may be the CR of a CRLF that does not count.
      if (c.input.size() > limits_.max_line_bytes + 1) {
        c.input.clear();
        c.discarding = true;
        stats_.overlong_lines.fetch_add(1, std::memory_order_relaxed);
        queue(c, handler_.on_overlong_line(c.id));
      }
      break;
    }
    // A complete line: straight from the chunk when nothing was buffered before.
    std::string_view line = data.substr(0, lf);
    if (!c.input.empty()) {
      c.input.append(line);
      line = c.input;
    }
    if (!line.empty() && line.back() == '\r')
      line.remove_suffix(1);
    if (line.size() > limits_.max_line_bytes) {
      stats_.overlong_lines.fetch_add(1, std::memory_order_relaxed);
      queue(c, handler_.on_overlong_line(c.id));
    } else {
      queue(c, handler_.on_line(c.id, line));
    }
    c.input.clear();
    data.remove_prefix(lf + 1);
  }
  c.unread.erase(0, c.unread.size() - data.size());
  close_if_done(c);
}

void LineServer::queue(Client& c, std::string&& answer) {
  if (answer.empty())
    return;
  if (c.pending() == 0) {
    c.output = std::move(answer);
    c.output_sent = 0;
    c.last_output = Clock::now();  // the send timeout runs from here
  } else {
    c.output += answer;
  }
  // Sending is normally left to the end of the turn (one send() for several answers); only when
  // the limit is crossed do we try to send now, and disconnect if the socket takes too little.
  if (c.pending() > limits_.max_pending_output_bytes) {
    flush(c);
    if (c.close == Client::Close::kNo && c.pending() > limits_.max_pending_output_bytes)
      c.close = Client::Close::kSlow;
  }
}

void LineServer::flush(Client& c) {
  while (c.pending() > 0) {
    // MSG_NOSIGNAL: a peer that has gone away gives EPIPE here instead of killing the process.
    const ssize_t n = ::send(c.fd, c.output.data() + c.output_sent, c.pending(), MSG_NOSIGNAL);
    if (n > 0) {
      c.output_sent += static_cast<std::size_t>(n);
      c.last_output = Clock::now();
      stats_.bytes_out.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && would_block(errno)) {
      break;
    } else {
      c.close = Client::Close::kNow;  // EPIPE, ECONNRESET, ...
      return;
    }
  }
  if (c.pending() == 0) {
    // Give back the memory of a large answer; keep a small buffer for the next ones.
    if (c.output.capacity() > kReadChunkBytes)
      std::string().swap(c.output);
    c.output.clear();
    c.output_sent = 0;
    close_if_done(c);
  } else if (c.output_sent > kReadChunkBytes && c.output_sent > c.output.size() / 2) {
    // Drop what is sent once it is most of the buffer: amortised O(1) per byte.
    c.output.erase(0, c.output_sent);
    c.output_sent = 0;
  }
}

void LineServer::close_marked_clients() {
  std::vector<ClientId> closed;
  for (Client& c : clients_) {
    if (c.close == Client::Close::kNo)
      continue;
    if (c.close == Client::Close::kSlow)
      stats_.disconnected_slow.fetch_add(1, std::memory_order_relaxed);
    if (c.close == Client::Close::kIdle)
      stats_.disconnected_idle.fetch_add(1, std::memory_order_relaxed);
    close_fd(c.fd);
    closed.push_back(c.id);
  }
  if (closed.empty())
    return;
  std::erase_if(clients_, [](const Client& c) { return c.fd < 0; });
  client_count_.store(clients_.size());
  for (ClientId id : closed)
    handler_.on_disconnect(id);
}

void LineServer::close_all_clients() {
  for (Client& c : clients_) {
    if (c.close != Client::Close::kNo)
      continue;  // already on its way out, with its reason
    if (c.pending() > 0)
      flush(c);  // best effort, non-blocking: whatever the socket takes now
    c.close = Client::Close::kNow;
  }
  close_marked_clients();
}

}  // namespace piezoshift::host
