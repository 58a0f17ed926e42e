#include "piezoshift/procedures/station_recorder.hpp"

#include <algorithm>
#include <string>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::procedures {

namespace {

constexpr std::array<RecorderSignal, kRecorderSignals> kAll{
    RecorderSignal::kTarget, RecorderSignal::kPosition, RecorderSignal::kInterferometer,
    RecorderSignal::kOutputV, RecorderSignal::kSensorUm};

}  // namespace

const char* to_string(RecorderSignal signal) noexcept {
  switch (signal) {
    case RecorderSignal::kTarget:
      return "target";
    case RecorderSignal::kPosition:
      return "position";
    case RecorderSignal::kInterferometer:
      return "interferometer";
    case RecorderSignal::kOutputV:
      return "output_V";
    case RecorderSignal::kSensorUm:
      return "sensor_um";
  }
  return "?";
}

RecorderSignal parse_recorder_signal(std::string_view name) {
  for (const RecorderSignal s : kAll)
    if (name == to_string(s))
      return s;
  throw core::InputError(fmt::format(
      "recorder signal '{}': not one of target, position, interferometer, output_V, sensor_um",
      name));
}

void StationRecorder::start(std::size_t points, std::uint64_t every,
                            std::vector<RecorderSignal> signals, std::uint64_t first_tick) {
  if (points < 1 || points > kMaxPoints)
    throw core::InputError(fmt::format("recorder samples {}: must be 1 to {}", points, kMaxPoints));
  if (every < 1 || every > kMaxEvery)
    throw core::InputError(
        fmt::format("recorder every {}: must be 1 to {} ticks", every, kMaxEvery));
  if (signals.empty())
    signals.assign(kAll.begin(), kAll.end());
  for (std::size_t i = 0; i < signals.size(); ++i)
    if (std::find(signals.begin(), signals.begin() + static_cast<std::ptrdiff_t>(i), signals[i]) !=
        signals.begin() + static_cast<std::ptrdiff_t>(i))
      throw core::InputError(
          fmt::format("recorder signal '{}': named twice", to_string(signals[i])));
  recording_ = Recording{};
  recording_.signals = std::move(signals);
  recording_.every = every;
  recording_.time_s.reserve(points);
  for (const RecorderSignal s : recording_.signals)
    recording_.values[static_cast<std::size_t>(s)].reserve(points);
  wanted_ = points;
  every_ = every;
  first_tick_ = first_tick;
  next_tick_ = first_tick;
}

void StationRecorder::take(std::uint64_t tick, double t_s, const host::RecorderInput& in) {
  if (!active() || complete() || tick < next_tick_)
    return;
  // A tick past the one due: the host link dropped the ticks between (counted, not recorded).
  if (tick > next_tick_) {
    recording_.ticks_missed += tick - next_tick_;
    if ((tick - first_tick_) % every_ != 0) {
      next_tick_ = first_tick_ + ((tick - first_tick_) / every_ + 1) * every_;
      return;
    }
  }
  recording_.time_s.push_back(t_s);
  for (const RecorderSignal s : recording_.signals) {
    auto& column = recording_.values[static_cast<std::size_t>(s)];
    switch (s) {
      case RecorderSignal::kTarget:
        column.push_back(in.target);
        break;
      case RecorderSignal::kPosition:
        column.push_back(in.position);
        break;
      case RecorderSignal::kInterferometer:
        column.push_back(in.interferometer);
        break;
      case RecorderSignal::kOutputV:
        column.push_back({in.channel_V[0], in.channel_V[1], in.channel_V[2]});
        break;
      case RecorderSignal::kSensorUm:
        column.push_back({in.sensor_um[0], in.sensor_um[1], in.sensor_um[2]});
        break;
    }
  }
  next_tick_ = tick + every_;
}

}  // namespace piezoshift::procedures
