#include "piezoshift/host/wave_generators.hpp"

#include <algorithm>

namespace piezoshift::host {

WaveGenerators::WaveGenerators(const StageModel& model)
    : model_(model), slots_(std::make_unique<std::array<Slot, 2 * kGenerators>>()) {}

GcsError WaveGenerators::define(int table, const std::vector<std::string_view>& args) {
  for (std::size_t g = 0; g < kGenerators; ++g) {
    if (running_[g] && table_[g] == table)
      return GcsError::kWaveGeneratorActive;  // its copy plays on; still, PI refuses it
  }
  return tables_.define(table, args);
}

GcsError WaveGenerators::select(const std::vector<Setting>& tables) {
  for (const auto& [g, t] : tables) {
    if (t < 0 || t > WaveTables::kTables)
      return GcsError::kWaveIndex;
    if (running_[g])
      return GcsError::kWaveGeneratorActive;
  }
  for (const auto& [g, t] : tables)
    table_[g] = static_cast<int>(t);
  return GcsError::kNone;
}

GcsError WaveGenerators::set_cycles(const std::vector<Setting>& cycles) {
  for (const auto& [g, n] : cycles) {
    if (n < 0 || n > kMaxCycles)
      return GcsError::kParamOutOfRange;
  }
  for (const auto& [g, n] : cycles)
    cycles_[g] = n;
  return GcsError::kNone;
}

GcsError WaveGenerators::check_rate(long long rate, long long interpolation) {
  return rate < 1 || rate > kMaxRate || interpolation != 0 ? GcsError::kParamOutOfRange
                                                           : GcsError::kNone;
}

unsigned WaveGenerators::running_mask() const {
  unsigned mask = 0;
  for (std::size_t g = 0; g < kGenerators; ++g)
    if (running_[g])
      mask |= 1u << g;
  return mask;
}

GcsError WaveGenerators::check_start(const std::array<bool, kGenerators>& start,
                                     const AxisValues& commanded) const {
  // The range each generator will span, and the poses at the corners of that box: a move
  // checked as a whole pose, as MOV is (the supervisor's limits hold whatever the check).
  std::array<double, kGenerators> lo{};
  std::array<double, kGenerators> hi{};
  for (std::size_t g = 0; g < kGenerators; ++g) {
    if (start[g]) {
      const int t = table_[g];
      if (t < 1 || tables_.values(t).empty())
        return GcsError::kWaveNotDefined;
      const auto [mn, mx] = std::minmax_element(tables_.values(t).begin(), tables_.values(t).end());
      lo[g] = *mn;
      hi[g] = *mx;
    } else if (running_[g]) {
      lo[g] = min_[g];
      hi[g] = max_[g];
    } else {
      lo[g] = hi[g] = commanded[g];
    }
  }
  for (unsigned corner = 0; corner < 8; ++corner) {
    AxisValues pose{};
    for (std::size_t g = 0; g < kGenerators; ++g)
      pose[g] = ((corner >> g) & 1u) != 0 ? hi[g] : lo[g];
    if (!model_.reachable(pose))
      return GcsError::kPositionOutOfLimits;
  }
  return GcsError::kNone;
}

std::size_t WaveGenerators::free_slot(std::size_t g) const {
  return slot_[g] == static_cast<int>(2 * g) ? 2 * g + 1 : 2 * g;
}

runtime::HostCommand WaveGenerators::start_command(std::size_t g, double reference) {
  const std::vector<double>& values = tables_.values(table_[g]);
  Slot& storage = (*slots_)[free_slot(g)];
  std::copy(values.begin(), values.end(), storage.begin());
  // Eq. 5 is linear in the pose: the points move by column_g per unit of axis g.
  AxisValues unit{};
  unit[g] = 1.0;
  const Vec3 zero = model_.points_for(AxisValues{});
  const Vec3 column = model_.points_for(unit);
  runtime::HostCommand c{};
  c.kind = runtime::HostCommand::Kind::kWave;
  c.wave.action = runtime::WaveCommand::Action::kStart;
  c.wave.generator = static_cast<std::uint8_t>(g);
  c.wave.values = storage.data();
  c.wave.length = static_cast<std::uint32_t>(values.size());
  c.wave.rate = static_cast<std::uint32_t>(rate_[g]);
  c.wave.cycles = static_cast<std::uint32_t>(cycles_[g]);
  for (std::size_t i = 0; i < 3; ++i)
    c.wave.points_per_unit[i] = column[i] - zero[i];
  c.wave.reference = reference;
  return c;
}

void WaveGenerators::started(std::size_t g, long long mode, std::uint64_t sequence) {
  slot_[g] = static_cast<int>(free_slot(g));
  sequence_[g] = sequence;
  mode_[g] = mode;
  running_[g] = true;
  const std::vector<double>& values = tables_.values(table_[g]);
  if (values.empty())
    return;  // check_start refuses an empty table (401); never read past the end regardless
  const auto [mn, mx] = std::minmax_element(values.begin(), values.end());
  min_[g] = *mn;
  max_[g] = *mx;
}

runtime::HostCommand WaveGenerators::stop_command(std::size_t g) {
  runtime::HostCommand c{};
  c.kind = runtime::HostCommand::Kind::kWave;
  c.wave.action = runtime::WaveCommand::Action::kStop;
  c.wave.generator = static_cast<std::uint8_t>(g);
  return c;
}

void WaveGenerators::stopped(std::size_t g, std::uint64_t sequence) {
  sequence_[g] = sequence;
  running_[g] = false;
  mode_[g] = 0;
}

unsigned WaveGenerators::update(std::uint64_t applied_sequence, std::uint8_t running_bits) {
  unsigned finished = 0;
  for (std::size_t g = 0; g < kGenerators; ++g) {
    if (!applied(g, applied_sequence))
      continue;  // from before the loop took g's last start or stop
    const bool running = ((running_bits >> g) & 1u) != 0;
    if (running_[g] && !running) {
      finished |= 1u << g;
      mode_[g] = 0;
    }
    running_[g] = running;
  }
  return finished;
}

}  // namespace piezoshift::host
