#include "piezoshift/host/poll_server.hpp"

#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::host {

namespace {

bool would_block(int err) {
  return err == EAGAIN || err == EWOULDBLOCK;
}

const PollServerLimits& checked(const PollServerLimits& limits, const std::string& name,
                                const std::string& where) {
  const auto fail = [&](const char* what) {
    throw core::InputError(fmt::format("{} on {}: {}", name, where, what));
  };
  if (limits.max_clients < 1)
    fail("max_clients must be at least 1");
  if (limits.read_budget_bytes < 1)
    fail("the read budget must be at least 1 byte");
  if (limits.max_pending_output_bytes < 1)
    fail("max_pending_output_bytes must be at least 1");
  if (!(limits.idle_timeout_s > 0.0))  // also rejects NaN
    fail("idle_timeout_s must be > 0 (+inf: no timeout)");
  if (!(limits.send_timeout_s > 0.0))
    fail("send_timeout_s must be > 0 (+inf: no timeout)");
  if (!(limits.evict_idle_when_full_s >= 0.0))
    fail("evict_idle_when_full_s must be >= 0 (+inf: never)");
  if (!(limits.evict_incomplete_when_full_s >= 0.0))
    fail("evict_incomplete_when_full_s must be >= 0 (+inf: never)");
  return limits;
}

}  // namespace

void PollProtocol::on_end_of_input(PollClient& client) {
  server().close(client);
}

PollServer::PollServer(const Ipv4Host& host, std::uint16_t port, const std::string& name,
                       const std::string& where, const PollServerLimits& limits,
                       PollProtocol& protocol)
    : limits_(checked(limits, name, where)),
      protocol_(protocol),
      name_(name),
      listener_(host, port, name, where),
      read_buffer_(limits.read_budget_bytes) {
  protocol_.server_ = this;
}

PollServer::~PollServer() {
  for (auto& c : clients_)
    close_fd(c->fd_);
}

void PollServer::stop() noexcept {
  stop_requested_.store(true);
  listener_.wake();
}

PollServerStats PollServer::stats() const {
  constexpr auto r = std::memory_order_relaxed;
  PollServerStats s;
  s.accepted = stats_.accepted.load(r);
  s.refused_max_clients = stats_.refused_max_clients.load(r);
  s.evicted_slow = stats_.evicted_slow.load(r);
  s.evicted_idle = stats_.evicted_idle.load(r);
  s.evicted_for_room = stats_.evicted_for_room.load(r);
  s.failed = stats_.failed.load(r);
  s.failed_rounds = stats_.failed_rounds.load(r);
  s.rounds = stats_.rounds.load(r);
  s.bytes_in = stats_.bytes_in.load(r);
  s.bytes_out = stats_.bytes_out.load(r);
  s.accept_failures = listener_.accept_failures();
  return s;
}

void PollServer::for_each_client(const std::function<void(PollClient&)>& visit) {
  for (auto& c : clients_)
    visit(*c);
}

void PollServer::run(const std::atomic<int>* stop_flag, int poll_interval_ms) {
  if (poll_interval_ms < 1)
    throw std::invalid_argument(name_ + " run: poll_interval_ms must be at least 1");
  const auto stopping = [&] {
    return stop_requested_.load() || (stop_flag != nullptr && stop_flag->load() != 0);
  };
  try {
    while (!stopping()) {
      try {
        protocol_.on_round();
      } catch (const std::exception&) {
        // Its work (e.g. the samples drained for the dashboard) is lost; the clients go on.
        stats_.failed_rounds.fetch_add(1, std::memory_order_relaxed);
      }
      close_marked_clients();  // what on_round() gave up (e.g. a request timeout)
      serve_round(poll_interval_ms);
      evict_stale_clients();
      close_marked_clients();
      // Accept after closing, so that a slot freed in this round is available at once.
      if (fds_[1].revents & POLLIN)
        accept_clients();
      stats_.rounds.fetch_add(1, std::memory_order_relaxed);
    }
  } catch (...) {
    close_all_clients();
    throw;
  }
  close_all_clients();
}

void PollServer::serve_round(int poll_interval_ms) {
  // Clients accepted later in this round are polled from the next one on.
  fds_.clear();
  fds_.push_back({listener_.wake_fd(), POLLIN, 0});
  fds_.push_back({listener_.poll_fd(), POLLIN, 0});  // -1 while accepting is paused
  bool work_left = false;
  for (const auto& c : clients_) {
    short events = !c->input_ended_ && protocol_.wants_input(*c) ? POLLIN : 0;
    if (c->pending() > 0)
      events |= POLLOUT;
    fds_.push_back({c->fd_, events, 0});
    work_left = work_left || protocol_.has_work(*c);
  }
  if (::poll(fds_.data(), fds_.size(), work_left ? 0 : poll_interval_ms) < 0) {
    if (errno == EINTR) {
      fds_[1].revents = 0;
      return;
    }
    throw std::runtime_error(fmt::format("{}: poll: {}", name_, std::strerror(errno)));
  }
  if (fds_[0].revents != 0)
    listener_.drain_wake();
  for (std::size_t i = 0; i + 2 < fds_.size(); ++i) {
    PollClient& c = *clients_[i];
    const short revents = fds_[i + 2].revents;
    if (revents & POLLNVAL)
      c.close_ = PollClient::Close::kNow;
    if (c.closing())
      continue;
    // A client whose request throws (std::bad_alloc, a handler's bug) is closed: it fails alone,
    // the others are served.
    try {
      // POLLHUP/POLLERR: recv() or send() reports what happened.
      if ((fds_[i + 2].events & POLLIN) && (revents & (POLLIN | POLLHUP | POLLERR)))
        read_from(c);
      if (!c.closing())
        protocol_.serve(c);
      if (!c.closing() && c.pending() > 0)
        flush(c);
    } catch (const std::exception&) {
      c.close_ = PollClient::Close::kFailed;
    }
  }
}

void PollServer::accept_clients() {
  for (;;) {
    const int fd = listener_.accept_client();
    if (fd < 0)
      return;
    if (clients_.size() >= limits_.max_clients && make_room())
      close_marked_clients();
    if (clients_.size() >= limits_.max_clients) {
      // Accept and close rather than leave it in the backlog: the peer learns at once.
      stats_.refused_max_clients.fetch_add(1, std::memory_order_relaxed);
      const std::string last_words = protocol_.refusal();
      if (!last_words.empty() &&
          ::send(fd, last_words.data(), last_words.size(), MSG_NOSIGNAL | MSG_DONTWAIT) < 0) {
        // Best effort: the peer may be gone already.
      }
      ::close(fd);
      continue;
    }
    std::unique_ptr<PollClient> c = protocol_.make_client();
    c->fd_ = fd;
    c->id_ = next_id_++;
    c->last_input_ = Clock::now();
    clients_.push_back(std::move(c));
    client_count_.store(clients_.size());
    stats_.accepted.fetch_add(1, std::memory_order_relaxed);
    try {
      protocol_.on_connect(*clients_.back());
    } catch (const std::exception&) {
      clients_.back()->close_ = PollClient::Close::kFailed;
    }
  }
}

bool PollServer::make_room() {
  const auto at_least = [](double s) {
    return s < std::numeric_limits<double>::infinity()
               ? std::optional(
                     std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s)))
               : std::nullopt;
  };
  const std::optional<Clock::duration> min_idle = at_least(limits_.evict_idle_when_full_s);
  const std::optional<Clock::duration> min_incomplete =
      at_least(limits_.evict_incomplete_when_full_s);
  const auto now = Clock::now();
  PollClient* idlest = nullptr;
  PollClient* stalled = nullptr;  // its request incomplete the longest
  Clock::time_point stalled_since{};
  for (auto& c : clients_) {
    // Only a client waiting for its peer: one whose input ended, or whose input the protocol does
    // not want (an answer on its way, a throttled reader), is busy by our side's doing.
    if (c->closing() || c->input_ended_ || !protocol_.wants_input(*c))
      continue;
    if (const auto since = protocol_.incomplete_since(*c);
        min_incomplete && since && now - *since >= *min_incomplete &&
        (stalled == nullptr || *since < stalled_since)) {
      stalled = c.get();
      stalled_since = *since;
    }
    if (min_idle && now - c->last_input_ >= *min_idle &&
        (idlest == nullptr || c->last_input_ < idlest->last_input_))
      idlest = c.get();  // ties: the older connection, met first
  }
  PollClient* chosen = stalled != nullptr ? stalled : idlest;
  if (chosen == nullptr)
    return false;
  chosen->close_ = PollClient::Close::kRoom;
  return true;
}

void PollServer::read_from(PollClient& c) {
  char* const buffer = read_buffer_.data();
  const ssize_t n = ::recv(c.fd_, buffer, read_buffer_.size(), 0);
  if (n > 0) {
    stats_.bytes_in.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
    c.last_input_ = Clock::now();
    protocol_.on_input(c, std::string_view(buffer, static_cast<std::size_t>(n)));
  } else if (n == 0) {
    c.input_ended_ = true;
    protocol_.on_end_of_input(c);
  } else if (errno != EINTR && !would_block(errno)) {
    c.close_ = PollClient::Close::kNow;  // ECONNRESET and the like
  }
}

void PollServer::queue(PollClient& c, std::string_view bytes) {
  if (bytes.empty() || c.closing())
    return;
  if (c.pending() == 0) {
    c.output_.assign(bytes);
    c.output_sent_ = 0;
    c.last_output_ = Clock::now();  // the send timeout runs from here
  } else {
    c.output_.append(bytes);
  }
  // Sending is normally left to the end of the round (one send() for several answers); only when
  // the bound is crossed do we try now, and evict if the socket takes too little.
  if (c.pending() > limits_.max_pending_output_bytes) {
    flush(c);
    if (!c.closing() && c.pending() > limits_.max_pending_output_bytes)
      c.close_ = PollClient::Close::kSlow;
  }
}

void PollServer::flush(PollClient& c) {
  while (c.pending() > 0) {
    // MSG_NOSIGNAL: a peer that has gone away gives EPIPE here instead of killing the process.
    const ssize_t n = ::send(c.fd_, c.output_.data() + c.output_sent_, c.pending(), MSG_NOSIGNAL);
    if (n > 0) {
      c.output_sent_ += static_cast<std::size_t>(n);
      c.last_output_ = Clock::now();
      stats_.bytes_out.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && would_block(errno)) {
      break;
    } else {
      c.close_ = PollClient::Close::kNow;  // EPIPE, ECONNRESET, ...
      return;
    }
  }
  if (c.pending() == 0) {
    // Give back the memory of a large answer; keep a small buffer for the next ones.
    if (c.output_.capacity() > read_buffer_.size())
      std::string().swap(c.output_);
    c.output_.clear();
    c.output_sent_ = 0;
    if (c.finishing_ && !c.closing())
      c.close_ = PollClient::Close::kNow;
  } else if (c.output_sent_ > read_buffer_.size() && c.output_sent_ > c.output_.size() / 2) {
    // Drop what is sent once it is most of the buffer: amortised O(1) per byte.
    c.output_.erase(0, c.output_sent_);
    c.output_sent_ = 0;
  }
}

void PollServer::finish(PollClient& c) {
  c.finishing_ = true;
  if (c.pending() == 0 && !c.closing())
    c.close_ = PollClient::Close::kNow;
}

void PollServer::close(PollClient& c) noexcept {
  if (!c.closing())
    c.close_ = PollClient::Close::kNow;
}

void PollServer::evict_stale_clients() {
  const auto limit = [](double s) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  };
  const bool idle_limited = std::isfinite(limits_.idle_timeout_s);
  const bool send_limited = std::isfinite(limits_.send_timeout_s);
  const auto now = Clock::now();
  for (auto& c : clients_) {
    if (c->closing())
      continue;
    // Input the protocol does not want (e.g. a throttled client's) waits by our choice: the send
    // timeout judges that client.
    if (idle_limited && !c->input_ended_ && protocol_.wants_input(*c) &&
        now - c->last_input_ > limit(limits_.idle_timeout_s))
      c->close_ = PollClient::Close::kIdle;
    else if (send_limited && c->pending() > 0 &&
             now - c->last_output_ > limit(limits_.send_timeout_s))
      c->close_ = PollClient::Close::kSlow;
  }
}

void PollServer::close_marked_clients() {
  std::vector<std::unique_ptr<PollClient>> closed;
  for (auto& c : clients_) {
    if (!c->closing())
      continue;
    if (c->close_ == PollClient::Close::kSlow)
      stats_.evicted_slow.fetch_add(1, std::memory_order_relaxed);
    if (c->close_ == PollClient::Close::kIdle)
      stats_.evicted_idle.fetch_add(1, std::memory_order_relaxed);
    if (c->close_ == PollClient::Close::kRoom)
      stats_.evicted_for_room.fetch_add(1, std::memory_order_relaxed);
    if (c->close_ == PollClient::Close::kFailed)
      stats_.failed.fetch_add(1, std::memory_order_relaxed);
    close_fd(c->fd_);
    closed.push_back(std::move(c));
  }
  if (closed.empty())
    return;
  std::erase_if(clients_, [](const auto& c) { return c == nullptr; });
  client_count_.store(clients_.size());
  for (auto& c : closed)
    protocol_.on_disconnect(*c);
}

void PollServer::close_all_clients() {
  for (auto& c : clients_) {
    if (c->closing())
      continue;  // already on its way out, with its reason
    if (c->pending() > 0)
      flush(*c);  // best effort, non-blocking: whatever the socket takes now
    c->close_ = PollClient::Close::kNow;
  }
  close_marked_clients();
}

}  // namespace piezoshift::host
