#include "piezoshift/host/line_server.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/host/http_line.hpp"

namespace piezoshift::host {

struct LineServer::Client : PollClient {
  std::string unread;       // received, not handled yet (at most one read chunk)
  std::string input;        // the partial line received so far (at most max_line_bytes + 1)
  bool discarding = false;  // inside an overlong line: drop bytes up to the next LF
  bool first_line = true;   // no line (nor overlong one) handled yet
  std::chrono::steady_clock::time_point partial_since;  // the first byte of input (or discarding)
};

namespace {

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
  if (!(limits.turn_budget_s > 0.0))
    fail("turn_budget_s must be > 0 (+inf: lines and bytes alone bound a turn)");
}

}  // namespace

LineServer::Client& LineServer::client(PollClient& c) noexcept {
  return static_cast<Client&>(c);
}

const LineServer::Client& LineServer::client(const PollClient& c) noexcept {
  return static_cast<const Client&>(c);
}

LineServer::LineServer(const ListenAddress& address, const LineServerLimits& limits,
                       LineHandler& handler)
    : limits_(limits), handler_(handler) {
  const std::string where = fmt::format("{}:{}", address.host, address.port);
  check_limits(limits, where);

  const Ipv4Host ip = parse_ipv4_host(address.host, "TCP server", where);
  if (!ip.loopback && !address.allow_remote)
    throw core::InputError(fmt::format(
        "TCP server on {} refuses non-loopback address {} without --allow-remote (GCS has no "
        "authentication: anyone who reaches the port moves the stage)",
        where, address.host));
  PollServerLimits core;
  core.max_clients = limits.max_clients;
  core.read_budget_bytes = kReadChunkBytes;
  core.max_pending_output_bytes = limits.max_pending_output_bytes;
  core.send_timeout_s = limits.send_timeout_s;
  core.idle_timeout_s = limits.idle_timeout_s;
  core.evict_idle_when_full_s = limits.evict_idle_when_full_s;
  core.evict_incomplete_when_full_s = limits.evict_incomplete_when_full_s;
  core_ = std::make_unique<PollServer>(ip, address.port, "TCP server", where, core,
                                       static_cast<PollProtocol&>(*this));
}

LineServer::~LineServer() = default;

void LineServer::run(const std::atomic<int>* stop_flag, int poll_interval_ms) {
  if (poll_interval_ms < 1)
    throw std::invalid_argument("LineServer::run: poll_interval_ms must be at least 1");
  core_->run(stop_flag, poll_interval_ms);
}

void LineServer::stop() noexcept {
  core_->stop();
}

LineServerStats LineServer::stats() const {
  const PollServerStats c = core_->stats();
  LineServerStats s;
  s.accepted = c.accepted;
  s.refused_max_clients = c.refused_max_clients;
  s.disconnected_slow = c.evicted_slow;
  s.disconnected_idle = c.evicted_idle;
  s.evicted_for_room = c.evicted_for_room;
  s.rounds = c.rounds;
  s.overlong_lines = overlong_lines_.load(std::memory_order_relaxed);
  s.refused_http = refused_http_.load(std::memory_order_relaxed);
  s.failed = c.failed;
  s.bytes_in = c.bytes_in;
  s.bytes_out = c.bytes_out;
  s.accept_failures = c.accept_failures;
  return s;
}

std::unique_ptr<PollClient> LineServer::make_client() {
  return std::make_unique<Client>();
}

void LineServer::on_connect(PollClient& c) {
  handler_.on_connect(c.id());
}

void LineServer::on_disconnect(PollClient& c) {
  handler_.on_disconnect(c.id());
}

bool LineServer::throttled(const PollClient& c) const {
  return c.pending() >= limits_.output_high_water_bytes;
}

bool LineServer::wants_input(const PollClient& c) const {
  return client(c).unread.empty() && !throttled(c);
}

std::optional<std::chrono::steady_clock::time_point> LineServer::incomplete_since(
    const PollClient& polled) const {
  const Client& c = client(polled);
  if (c.input.empty() && !c.discarding)
    return std::nullopt;
  return c.partial_since;
}

bool LineServer::has_work(const PollClient& c) const {
  return (!client(c).unread.empty() || handler_.answer_pending(c.id())) && !throttled(c);
}

void LineServer::on_input(PollClient& c, std::string_view bytes) {
  client(c).unread.assign(bytes);
}

void LineServer::on_end_of_input(PollClient& c) {
  // The peer may have only shut down its sending side (`printf '*IDN?\n' | nc -N ...`), so its
  // lines already received are handled and its answers still sent; a partial last line without
  // LF is dropped.
  finish_if_done(client(c));
}

void LineServer::finish_if_done(Client& c) {
  if (c.input_ended() && c.unread.empty() && !handler_.answer_pending(c.id()))
    core_->finish(c);
}

void LineServer::serve(PollClient& polled) {
  Client& c = client(polled);
  if ((c.unread.empty() && !handler_.answer_pending(c.id())) || throttled(c))
    return;
  std::string_view data = c.unread;
  std::size_t handled = 0;
  const auto answer = [&](std::string&& bytes) { core_->queue(c, bytes); };
  // The first line always runs; before each further one the clock is read.
  const auto turn_end = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(std::min(limits_.turn_budget_s, 1e6)));
  const auto within_turn = [&] {
    return handled == 0 || std::chrono::steady_clock::now() < turn_end;
  };
  while (!c.closing() && handled < kLinesPerTurn && !throttled(c) && within_turn()) {
    if (handler_.answer_pending(c.id())) {
      ++handled;
      answer(handler_.more_answer(c.id()));
      continue;
    }
    if (data.empty())
      break;
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
      answer(handler_.on_immediate(c.id(), data.front()));
      data.remove_prefix(1);
      continue;
    }
    if (lf == std::string_view::npos) {
      if (c.input.empty())
        c.partial_since = std::chrono::steady_clock::now();
      c.input.append(data);
      data = {};
      // One byte of slack: the last byte may be the CR of a CRLF that does not count.
      if (c.input.size() > limits_.max_line_bytes + 1) {
        c.first_line = false;
        c.input.clear();
        c.discarding = true;
        overlong_lines_.fetch_add(1, std::memory_order_relaxed);
        answer(handler_.on_overlong_line(c.id()));
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
    if (std::exchange(c.first_line, false) && limits_.refuse_http && looks_like_http(line)) {
      // Another protocol's request (a browser's or curl's POST): none of it runs.
      refused_http_.fetch_add(1, std::memory_order_relaxed);
      core_->close(c);
      data = {};
      break;
    }
    if (line.size() > limits_.max_line_bytes) {
      overlong_lines_.fetch_add(1, std::memory_order_relaxed);
      answer(handler_.on_overlong_line(c.id()));
    } else {
      answer(handler_.on_line(c.id(), line));
    }
    c.input.clear();
    data.remove_prefix(lf + 1);
  }
  c.unread.erase(0, c.unread.size() - data.size());
  finish_if_done(c);
}

}  // namespace piezoshift::host
