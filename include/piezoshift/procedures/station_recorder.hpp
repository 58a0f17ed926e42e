#pragma once
// The loop station's data recorder (loop_station.hpp). It records what GCS's recorder does
// (host/data_recorder.hpp: DRC options 1, 2, 90, 7 and 17), one point every `every` ticks, and
// hands the numbers back as numbers rather than DRR?'s text:
//
//   target          the pose the loop is asked for (MOV?)          [Z um, tip urad, tilt urad]
//   position        the pose the strain gauges say (POS?)          [Z um, tip urad, tilt urad]
//   interferometer  the twin's interferometer as a pose            NaN on hardware
//   output_V        the amplifier outputs of channels 1..3         V (0-150 V)
//   sensor_um       the strain gauges of channels 1..3             um of actuator stroke
//
// Every point also has its time on the loop's clock (time_s, from the loop's start). A point the
// host link dropped (the host did not drain the loop's ring for ~4 s) is counted, not recorded.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "piezoshift/host/data_recorder.hpp"

namespace piezoshift::procedures {

enum class RecorderSignal : std::uint8_t {
  kTarget,
  kPosition,
  kInterferometer,
  kOutputV,
  kSensorUm
};
inline constexpr std::size_t kRecorderSignals = 5;

//! "target", "position", "interferometer", "output_V", "sensor_um".
const char* to_string(RecorderSignal signal) noexcept;
//! core::InputError naming the text and the signals there are.
RecorderSignal parse_recorder_signal(std::string_view name);

struct Recording {
  std::vector<RecorderSignal> signals;  //!< what was recorded, in the order asked
  std::uint64_t every = 1;              //!< ticks between two points
  std::vector<double> time_s;           //!< each point's time since the loop started
  //! Per signal (indexed by RecorderSignal), one value triple per point; empty when not recorded.
  std::array<std::vector<std::array<double, 3>>, kRecorderSignals> values;
  std::uint64_t ticks_missed = 0;  //!< ticks of the recording the host link dropped

  const std::vector<std::array<double, 3>>& of(RecorderSignal s) const {
    return values[static_cast<std::size_t>(s)];
  }
};

class StationRecorder {
 public:
  //! A recording's points at most: 200 s of every tick at 1 kHz, 24 MB per signal.
  static constexpr std::size_t kMaxPoints = 200000;
  static constexpr std::uint64_t kMaxEvery = 1000000;  //!< as GCS's RTR (DataRecorder::kMaxRate)

  //! Starts a recording of `points` points, one every `every` ticks, from tick first_tick on;
  //! empty signals: all five. core::InputError naming the argument when points is not in
  //! [1, kMaxPoints], every not in [1, kMaxEvery] or a signal is named twice.
  void start(std::size_t points, std::uint64_t every, std::vector<RecorderSignal> signals,
             std::uint64_t first_tick);
  //! One tick's values; kept when the recording wants that tick.
  void take(std::uint64_t tick, double t_s, const host::RecorderInput& in);
  bool active() const noexcept { return wanted_ > 0; }
  std::size_t wanted() const noexcept { return wanted_; }
  bool complete() const noexcept { return wanted_ > 0 && recording_.time_s.size() >= wanted_; }
  //! The tick the last point wants (complete() once it is taken).
  std::uint64_t last_tick() const noexcept { return first_tick_ + (wanted_ - 1) * every_; }
  const Recording& recording() const noexcept { return recording_; }

 private:
  Recording recording_;
  std::size_t wanted_ = 0;
  std::uint64_t every_ = 1;
  std::uint64_t first_tick_ = 0;
  std::uint64_t next_tick_ = 0;  // the next tick a point is due at
};

}  // namespace piezoshift::procedures
