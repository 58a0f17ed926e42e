// The GCS wave generator commands: WAV, WSL, WGC, WTR, WGO, WGR and their queries, and the
// starting and stopping of a generator.
#include "piezoshift/host/gcs_interpreter.hpp"

#include <algorithm>
#include <chrono>
#include <thread>
#include <utility>

#include <fmt/core.h>

#include "gcs_arguments.hpp"

namespace piezoshift::host {

using namespace gcs;

namespace {

constexpr std::size_t kGenerators = WaveGenerators::kGenerators;

}  // namespace

std::string GcsInterpreter::wave_define(Session& s, const Args& args) {
  if (args.size() < 3) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  long long table = 0;
  if (!parse_integer(args[0], table)) {
    fail(s, GcsError::kParamSyntax);
    return {};
  }
  const int t = static_cast<int>(std::clamp<long long>(table, -1, 1000));
  accepted(s, waves_.define(t, Args(args.begin() + 1, args.end())));
  return {};
}

std::string GcsInterpreter::wave_query(Session& s, const Args& args) {
  std::vector<std::string> lines;
  const auto line = [&](int t) {
    lines.push_back(fmt::format("{} 1={}", t, waves_.tables().values(t).size()));
  };
  if (args.empty()) {
    for (int t = 1; t <= WaveTables::kTables; ++t)
      line(t);
    return framed(lines);
  }
  if (args.size() % 2 != 0 || args.size() > 2 * kMaxQueryItems) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  for (std::size_t i = 0; i < args.size(); i += 2) {
    long long t = 0;
    long long param = 0;
    if (!parse_integer(args[i], t) || !parse_integer(args[i + 1], param)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    if (t < 1 || t > WaveTables::kTables) {
      fail(s, GcsError::kWaveIndex);
      return {};
    }
    if (param != 1) {  // 1: the number of points, the one parameter PI defines for WAV?
      fail(s, GcsError::kParamOutOfRange);
      return {};
    }
    line(static_cast<int>(t));
  }
  return framed(lines);
}

std::string GcsInterpreter::wave_select(Session& s, const Args& args) {
  std::vector<WaveGenerators::Setting> tables;
  if (accepted(s, generator_pairs(args, kGenerators, tables)))
    accepted(s, waves_.select(tables));
  return {};
}

std::string GcsInterpreter::wave_select_query(Session& s, const Args& args) {
  std::string answer;
  const auto table = [this](std::size_t g) { return fmt::format("{}", waves_.table(g)); };
  return reply(s, generator_lines(args, table, answer), answer);
}

std::string GcsInterpreter::wave_cycles(Session& s, const Args& args) {
  std::vector<WaveGenerators::Setting> cycles;
  if (accepted(s, generator_pairs(args, kGenerators, cycles)))
    accepted(s, waves_.set_cycles(cycles));
  return {};
}

std::string GcsInterpreter::wave_cycles_query(Session& s, const Args& args) {
  std::string answer;
  const auto cycles = [this](std::size_t g) { return fmt::format("{}", waves_.cycles(g)); };
  return reply(s, generator_lines(args, cycles, answer), answer);
}

std::string GcsInterpreter::wave_rate(Session& s, const Args& args) {
  // "{generator} {rate} {interpolation}" triples; generator 0: all.
  if (args.empty() || args.size() % 3 != 0) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  std::vector<std::pair<std::size_t, long long>> set;
  for (std::size_t i = 0; i < args.size(); i += 3) {
    long long g = 0;
    long long rate = 0;
    long long interpolation = 0;
    if (!parse_integer(args[i], g) || !parse_integer(args[i + 1], rate) ||
        !parse_integer(args[i + 2], interpolation)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    if (g < 0 || g > static_cast<long long>(kGenerators)) {
      fail(s, GcsError::kWaveIndex);
      return {};
    }
    if (!accepted(s, WaveGenerators::check_rate(rate, interpolation)))
      return {};
    for (std::size_t k = 0; k < kGenerators; ++k)
      if (g == 0 || static_cast<std::size_t>(g - 1) == k)
        set.emplace_back(k, rate);
  }
  for (const auto& [g, rate] : set)
    waves_.set_rate(g, rate);
  return {};
}

std::string GcsInterpreter::wave_rate_query(Session& s, const Args& args) {
  std::string answer;
  const auto rate = [this](std::size_t g) { return fmt::format("{} 0", waves_.rate(g)); };
  return reply(s, generator_lines(args, rate, answer), answer);
}

std::string GcsInterpreter::wave_start(Session& s, const Args& args) {
  std::vector<WaveGenerators::Setting> pairs;
  if (!accepted(s, generator_pairs(args, kGenerators, pairs)))
    return {};
  std::array<bool, kGenerators> start{};
  for (const auto& [g, mode] : pairs) {
    if (mode != 0 && mode != 1) {  // 1: start now; PI's other bits (triggers, offsets) are not here
      fail(s, GcsError::kWgoBitNotSupported);
      return {};
    }
    start[g] = mode == 1;
  }
  const bool any_start = std::find(start.begin(), start.end(), true) != start.end();
  if (any_start) {
    if (!servo_on_ || faulted_) {
      fail(s, GcsError::kServoOff);
      return {};
    }
    if (!accepted(s, waves_.check_start(start, commanded())))
      return {};
  }
  for (const auto& [g, mode] : pairs) {
    const bool done = mode == 0 ? !waves_.active(g) || stop_wave(s, g) : start_wave(s, g, mode);
    if (!done)
      return {};
  }
  if (any_start) {
    settled_ = {};
    trigger_.motion(sequence_);
  }
  return {};
}

bool GcsInterpreter::start_wave(Session& s, std::size_t g, long long mode) {
  // The slot the loop does not read is free once it has applied g's last start or stop.
  if (!slot_free(g)) {
    fail(s, GcsError::kCommunication);
    return false;
  }
  if (!send(s, waves_.start_command(g, target_[g])))
    return false;
  waves_.started(g, mode, sequence_);
  return true;
}

std::string GcsInterpreter::wave_start_query(Session& s, const Args& args) {
  std::string answer;
  const auto mode = [this](std::size_t g) { return fmt::format("{}", waves_.mode(g)); };
  return reply(s, generator_lines(args, mode, answer), answer);
}

std::string GcsInterpreter::wave_running_query(Session&, const Args&) {
  return fmt::format("{:X}\n", waves_.running_mask());
}

std::string GcsInterpreter::wave_record_restart(Session&, const Args&) {
  trigger_.restart(sequence_);
  return {};
}

std::string GcsInterpreter::wave_generators(Session&, const Args&) {
  return fmt::format("{}\n", kGenerators);
}

bool GcsInterpreter::stop_waves(Session& s) {
  for (std::size_t g = 0; g < kGenerators; ++g)
    if (waves_.active(g) && !stop_wave(s, g))
      return false;
  return true;
}

bool GcsInterpreter::stop_wave(Session& s, std::size_t g) {
  const AxisValues now = commanded();
  if (!send(s, WaveGenerators::stop_command(g)))
    return false;
  if (waves_.running(g)) {
    target_[g] = now[g];  // where the loop folds it, to within the ticks until it applies this
    measured_target_[g] = false;
  }
  waves_.stopped(g, sequence_);
  return true;
}

bool GcsInterpreter::slot_free(std::size_t g) {
  for (int i = 0; i < 50 && !waves_.applied(g, last_.applied_sequence); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    drain();
  }
  return waves_.applied(g, last_.applied_sequence);
}

}  // namespace piezoshift::host
