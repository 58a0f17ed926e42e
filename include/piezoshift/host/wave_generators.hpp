#pragma once
// The wave generators of `piezoshift serve` as PI's GCS 2.0 models them (docs/gcs.md, "Wave
// generator"), on the host's side: generator g (0-based here, 1..3 in GCS) plays the wave table
// WSL selects (WAV defines it, WaveTables) into axis g (Z, U, V), one table point every WTR
// servo cycles, WGC times (0: until stopped); WGO starts and stops it. This class holds the
// settings, what the loop last said of each generator and the fixed slots the loop plays from;
// it parses no command (the interpreter does) and sends nothing: it builds the kWave commands
// and is told when they were sent. The loop's side is runtime/wave_generator.hpp.
//
//   slots     two per generator, allocated once: the one playing and the one the next start
//             fills. A start copies the table into the slot the loop does not read, and only
//             once the loop has applied the generator's last start or stop (applied()), so the
//             loop never reads a slot being written.
//   running   set by a start or stop at once (the interpreter's view), then as the samples say
//             from the first sample whose tick applied that start or stop
// Not thread-safe: the server's one network thread owns it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "piezoshift/host/gcs_error.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/host/wave_tables.hpp"
#include "piezoshift/runtime/host_link.hpp"

namespace piezoshift::host {

class WaveGenerators {
 public:
  static constexpr std::size_t kGenerators = 3;
  static constexpr long long kMaxRate = 1000000;       //!< WTR, servo cycles per point
  static constexpr long long kMaxCycles = 0xFFFFFFFF;  //!< WGC (the loop counts in 32 bits)
  //! One "{generator} {value}" of WSL or WGC, the generator 0-based.
  using Setting = std::pair<std::size_t, long long>;

  //! model maps an axis to the three points (a start's points_per_unit) and checks poses.
  explicit WaveGenerators(const StageModel& model);

  const WaveTables& tables() const noexcept { return tables_; }
  //! WAV: the table's definition; refused (73) while a running generator plays it.
  GcsError define(int table, const std::vector<std::string_view>& args);

  //! WSL, all or nothing: tables 0..WaveTables::kTables (400), not of a running generator (73).
  GcsError select(const std::vector<Setting>& tables);
  //! WGC, all or nothing: cycles in 0..kMaxCycles (17).
  GcsError set_cycles(const std::vector<Setting>& cycles);
  //! WTR's check of one rate and interpolation: 17 unless rate is in 1..kMaxRate and
  //! interpolation 0 (none; PI's others are not implemented).
  static GcsError check_rate(long long rate, long long interpolation);
  void set_rate(std::size_t g, long long rate) { rate_[g] = rate; }

  int table(std::size_t g) const { return table_[g]; }
  long long cycles(std::size_t g) const { return cycles_[g]; }
  long long rate(std::size_t g) const { return rate_[g]; }
  //! WGO?: the start mode last set, 0 again once the generator has stopped.
  long long mode(std::size_t g) const { return mode_[g]; }
  bool running(std::size_t g) const { return running_[g]; }
  //! Running or started and not yet stopped: what STP must stop.
  bool active(std::size_t g) const { return running_[g] || mode_[g] != 0; }
  //! #9: bit g set while generator g runs.
  unsigned running_mask() const;
  //! Whether the loop has applied g's last start or stop, given a sample's applied_sequence.
  bool applied(std::size_t g, std::uint64_t applied_sequence) const {
    return applied_sequence >= sequence_[g];
  }
  //! Whether axis g follows the wave in a sample: g runs and the loop has applied its start.
  bool playing(std::size_t g, std::uint64_t applied_sequence) const {
    return running_[g] && applied(g, applied_sequence);
  }

  //! WGO 1's check, the generators in `start` to be started: 401 when one's table is empty; 7
  //! when a corner of the box the generators span is unreachable (a starting one its table's
  //! range, a running one the range of the table it plays, the others `commanded`).
  GcsError check_start(const std::array<bool, kGenerators>& start,
                       const AxisValues& commanded) const;
  //! The kWave start of generator g from the axis value `reference`: its table copied into the
  //! slot the loop does not read (call only when applied()). started() once it is sent.
  runtime::HostCommand start_command(std::size_t g, double reference);
  void started(std::size_t g, long long mode, std::uint64_t sequence);
  //! The kWave stop of generator g; stopped() once it is sent.
  static runtime::HostCommand stop_command(std::size_t g);
  void stopped(std::size_t g, std::uint64_t sequence);
  //! A sample from the loop; returns the generators it reports stopped (bit g) that were
  //! running: their axes hold where the wave ended.
  unsigned update(std::uint64_t applied_sequence, std::uint8_t running_bits);

 private:
  using Slot = std::array<double, WaveTables::kPoints>;
  //! The slot of g's pair that the loop does not read.
  std::size_t free_slot(std::size_t g) const;

  const StageModel& model_;
  WaveTables tables_;
  std::unique_ptr<std::array<Slot, 2 * kGenerators>> slots_;
  std::array<int, kGenerators> table_{1, 2, 3};        // WSL
  std::array<long long, kGenerators> cycles_{};        // WGC, 0: until stopped
  std::array<long long, kGenerators> rate_{1, 1, 1};   // WTR
  std::array<long long, kGenerators> mode_{};          // WGO, as last set
  std::array<int, kGenerators> slot_{-1, -1, -1};      // the slot last handed over
  std::array<std::uint64_t, kGenerators> sequence_{};  // the last start/stop sent
  std::array<bool, kGenerators> running_{};
  std::array<double, kGenerators> min_{};  // range of the table playing
  std::array<double, kGenerators> max_{};
};

}  // namespace piezoshift::host
