#pragma once
// A LineHandler that takes a mutex around every call into another one: `piezoshift serve` with
// the dashboard (docs/dashboard.md) shares the GCS interpreter between the GCS network thread and
// the HTTP thread. The HTTP side holds the mutex only to copy samples out and to run its command
// lines, never across I/O, so a GCS answer waits at most that long.
#include <mutex>
#include <string>
#include <string_view>

#include "piezoshift/host/line_server.hpp"

namespace piezoshift::host {

class LockedLineHandler final : public LineHandler {
 public:
  LockedLineHandler(LineHandler& inner, std::mutex& mutex) : inner_(inner), mutex_(mutex) {}

  void on_connect(ClientId id) override {
    const std::lock_guard lock(mutex_);
    inner_.on_connect(id);
  }
  void on_disconnect(ClientId id) override {
    const std::lock_guard lock(mutex_);
    inner_.on_disconnect(id);
  }
  std::string on_line(ClientId id, std::string_view line) override {
    const std::lock_guard lock(mutex_);
    return inner_.on_line(id, line);
  }
  std::string on_overlong_line(ClientId id) override {
    const std::lock_guard lock(mutex_);
    return inner_.on_overlong_line(id);
  }
  // Without these two, GCS's single-character commands (#5, #7, #24, ...) would reach the
  // interpreter as line content whenever the dashboard runs.
  bool is_immediate(char byte) const override { return inner_.is_immediate(byte); }
  std::string on_immediate(ClientId id, char byte) override {
    const std::lock_guard lock(mutex_);
    return inner_.on_immediate(id, byte);
  }
  void on_poll() override {
    const std::lock_guard lock(mutex_);
    inner_.on_poll();
  }
  bool answer_pending(ClientId id) const override {
    const std::lock_guard lock(mutex_);
    return inner_.answer_pending(id);
  }
  std::string more_answer(ClientId id) override {
    const std::lock_guard lock(mutex_);
    return inner_.more_answer(id);
  }

 private:
  LineHandler& inner_;
  std::mutex& mutex_;
};

}  // namespace piezoshift::host
