#pragma once
// One opened emulated board: the ni_pcimio subdevice table (board_model.hpp) with the twin on
// its wires, executing Comedi instructions as the driver would.
//
// Wires: AO 0..2 drive the three amplifiers, AI 0..2 read the three gauge conditioners (the
// default channels of `--daq comedi:`); every other AI channel reads 0 V. DIO lines made outputs
// count their rising edges (a camera trigger's).
//
// Per transaction (comedi_do_insnlist or comedi_do_insn): the twin is first brought to the
// transaction's time with the outputs it held (settings.clock), then the instructions run in
// order as the kernel runs them: an AO write converts its raw code through the channel's DAC and
// goes out at once; an AI read converts the twin's latest gauge voltage through the channel's
// ADC in the range asked for (a gauge above a range reads maxdata). The first instruction that
// fails stops the list, which then fails as a whole with its errno (the kernel's
// do_insnlist_ioctl); the instructions before it have happened. Emulated: AI reads, AO writes
// and read-back, DIO 0 (reads, writes, INSN_BITS, direction configuration and query), and the
// special INSN_GTOD and INSN_WAIT; every other instruction fails with EINVAL, the errno of an
// instruction its subdevice has no handler for.
#include <comedilib.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "board_model.hpp"
#include "emulation_settings.hpp"
#include "piezoshift/plant/twin.hpp"

namespace piezoshift::emulation {

class EmulatedBoard {
 public:
  //! Builds the twin; throws core::InputError (a configuration that cannot make one).
  EmulatedBoard(EmulationSettings settings, BoardModel model);
  ~EmulatedBoard();
  EmulatedBoard(const EmulatedBoard&) = delete;
  EmulatedBoard& operator=(const EmulatedBoard&) = delete;

  const BoardModel& model() const noexcept { return model_; }
  const EmulationSettings& settings() const noexcept { return settings_; }

  //! The number of instructions done, or -1 with errno set.
  int do_insnlist(comedi_insnlist& list);
  //! The most samples one instruction may carry (the kernel's MAX_SAMPLES).
  static constexpr unsigned kMaxSamples = 65536;

  //! Writes the record files (settings.record, settings.series), if asked for.
  void write_records() const;

 private:
  //! A transaction after a longer stall advances the twin this much and drops the rest.
  static constexpr double kMaxCatchUp_s = 1.0;
  void advance_to_now();
  // Each returns the instruction's result (its sample count) or -errno.
  int execute(comedi_insn& insn);
  int check(const comedi_insn& insn) const;
  int special(comedi_insn& insn);  // INSN_GTOD, INSN_WAIT, INSN_INTTRIG
  int analog_in(comedi_insn& insn, const SubdeviceModel& s);
  int analog_out(comedi_insn& insn, const SubdeviceModel& s);
  int digital_io(comedi_insn& insn, const SubdeviceModel& s);
  int dio_config(comedi_insn& insn, std::uint32_t bit);
  void set_dio_levels(std::uint32_t mask, std::uint32_t bits);
  void sample_series();
  double elapsed_s() const;

  EmulationSettings settings_;
  BoardModel model_;
  std::unique_ptr<plant::Twin> twin_;
  std::mutex mutex_;  // a client may call from its loop thread and its main thread

  bool started_ = false;
  std::chrono::steady_clock::time_point start_{};
  std::int64_t steps_ = 0;  // twin steps of settings_.step_s done since the start
  std::uint64_t transactions_ = 0;
  std::uint64_t failed_transactions_ = 0;
  std::array<lsampl_t, 4> ao_codes_{};
  std::array<double, 4> ao_V_{};
  std::array<lsampl_t, 4> ao_readback_{};  // what an AO read returns: 0 until written
  std::uint32_t dio_output_ = 0;           // subdevice 2's lines made outputs (bit mask)
  std::uint32_t dio_level_ = 0;
  std::uint64_t dio_rising_edges_ = 0;
  std::uint64_t failed_ai_timeout_ = 0, failed_ao_busy_ = 0, failed_io_ = 0, ai_open_reads_ = 0;
  double time_dropped_s_ = 0.0;  // host stalls longer than kMaxCatchUp_s
  struct SeriesRow {
    double t_s;
    std::array<double, 3> ao_V, z_um, interferometer_um;
  };
  std::vector<SeriesRow> series_;
  void write_interferometer_logs();
  std::array<std::FILE*, 4> logs_{};  // P1, P2, P3, centre; null: not logging
  double next_log_s_ = 0.0;
  double unix_start_s_ = 0.0;  // the system clock at the first transaction
  double next_series_s_ = 0.0;
};

}  // namespace piezoshift::emulation
