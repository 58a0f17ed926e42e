#pragma once
// The GCS data recorder of `piezoshift serve` (DRC, DRC?, RTR, RTR?, DRL?, DRR?, TNR?):
// kTables record tables of up to kPoints points each, one point every `rate` servo cycles.
//
//   DRC t s o   table t (1..kTables) records option o of source s:
//                 0  nothing (the table is off)
//                 1  target position of axis s (Z, U, V)          MOV? value, um or urad
//                 2  current position of axis s                   POS? value, um or urad
//                 3  position error of axis s                     target - position
//                 7  voltage of output channel s (1, 2, 3)         amplifier output, V
//                 17 sensor of input channel s (1, 2, 3)           SGS, um of actuator stroke
//                 90 interferometer position of axis s (piezoshift: the twin's XL-80; NaN on
//                    hardware, which has no interferometer on line)
//               Options 1, 2, 3, 7 and 17 are PI's numbers for these signals.
//   trigger     recording restarts from point 1 whenever DRC or RTR changes the set-up, and as
//               DRT's trigger says (record_trigger.hpp; by default on every motion command);
//               it stops when kPoints are held.
//   DRR?        GCS's data form: "# KEY = value" header lines ending with "# END_HEADER", then one
//               line per point, columns separated by a space (SEPARATOR = 32). Made a part at a
//               time (start_read, continue_read: kValuesPerPart values, ~0.7 ms of formatting;
//               the whole of kMaxAnswerBytes took 11 ms of CPU), so that the server answers the
//               other clients between the parts; the values are copied when the read starts.
// Not thread-safe: the server's one network thread owns it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/host/gcs_error.hpp"
#include "piezoshift/host/stage_model.hpp"

namespace piezoshift::host {

//! What one servo cycle offers the recorder.
struct RecorderInput {
  AxisValues target{};          //!< MOV? values
  AxisValues position{};        //!< POS? values
  AxisValues interferometer{};  //!< NaN when there is none
  Vec3 channel_V{};             //!< amplifier outputs
  Vec3 sensor_um{};             //!< SGS in um
};

class DataRecorder {
 public:
  static constexpr int kTables = 8;
  static constexpr std::size_t kPoints = 8192;
  static constexpr int kMaxRate = 1000000;
  //! The largest DRR? answer: every point of every table, each value at most kValueBytes with its
  //! separator ("-1.23456789e-308 "), a line's " \n" counted in, and the header. About 1.1 MB.
  static constexpr std::size_t kValueBytes = 18;
  static constexpr std::size_t kHeaderBytes = 1024;
  static constexpr std::size_t kMaxAnswerBytes =
      kHeaderBytes + kPoints * static_cast<std::size_t>(kTables) * kValueBytes;
  //! Values formatted per part of a DRR? answer (whole rows, at least one).
  static constexpr std::size_t kValuesPerPart = 4096;

  //! A DRR? answer under way: the values it reads, copied when it started (at most kTables x
  //! kPoints doubles, 512 KiB), and how far it has got.
  struct Reading {
    std::vector<double> values;  //!< row after row, `columns` values each
    std::size_t columns = 0;
    std::size_t next = 0;  //!< the first value not in the answer yet
    bool pending() const noexcept { return next < values.size(); }
  };

  DataRecorder();

  //! DRC. kNone on success.
  GcsError configure(int table, std::string_view source, int option);
  //! DRC? answer body for one table, "Z 2" (or "0 0" when off). table must be valid.
  std::string describe_table(int table) const;
  bool table_exists(int table) const noexcept { return table >= 1 && table <= kTables; }

  GcsError set_rate(long long cycles);
  int rate() const noexcept { return rate_; }

  //! Recording from point 1 again (the trigger).
  void restart() noexcept;
  //! One servo cycle; stored when the cycle falls on the rate and there is room.
  void record(const RecorderInput& in);
  std::size_t points() const noexcept { return rows_.size(); }

  //! DRR? answer (GCS framing applied: every line but the last ends with " \n"). start is 1-based;
  //! count < 0: all from start; tables empty: every active table, else each named at most once
  //! (kParamSyntax when twice). Any start and count are safe; errors leave answer empty. The
  //! answer is at most kMaxAnswerBytes.
  GcsError read(long long start, long long count, const std::vector<int>& tables,
                double servo_cycle_s, std::string& answer) const;
  //! read() a part at a time: answer := the header, reading := the values to answer. Then
  //! continue_read() until !reading.pending(); the parts joined are read()'s answer.
  GcsError start_read(long long start, long long count, const std::vector<int>& tables,
                      double servo_cycle_s, std::string& answer, Reading& reading) const;
  //! Appends the next rows of reading, at most max(max_values, one row) values, to answer.
  static void continue_read(Reading& reading, std::string& answer, std::size_t max_values);

 private:
  struct Table {
    int option = 0;
    int source = 0;  // axis 0..2 or channel 0..2
  };
  double value(const Table& t, const RecorderInput& in) const;
  //! The tables a DRR? reads, validated (see read()).
  GcsError choose(const std::vector<int>& tables, std::vector<int>& chosen) const;
  std::string name(const Table& t) const;

  std::array<Table, kTables> tables_{};
  int rate_ = 1;
  std::uint64_t cycle_ = 0;
  std::vector<std::array<double, kTables>> rows_;
};

}  // namespace piezoshift::host
