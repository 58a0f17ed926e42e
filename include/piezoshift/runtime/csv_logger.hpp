#pragma once
// The logging thread: drains the loop's telemetry ring and streams it to a CSV file.
//
// Data safety:
//   - lines are formatted into a buffer and written with write(2) only as whole lines, at least
//     every flush_interval_s (0.25 s) and whenever 1 MiB is pending; the file is fdatasync()ed at
//     least every sync_interval_s (1 s) and on close. A process killed with SIGKILL therefore
//     leaves every tick up to the last flush, each on a complete line (a kill landing inside a
//     write(2) can leave one trailing partial line, without its newline; readers drop it).
//   - a write error (disk full, ...) stops logging, is kept in error(), and never reaches the
//     loop: the loop only ever does a non-blocking ring push.
//   - when the ring is full the loop drops the record and counts it (never blocks).
//
// Columns, all numeric so io::CsvTable reads them back (codes are documented in docs/runtime.md):
//   tick,t_s,zd1_um,zd2_um,zd3_um,s1_um,s2_um,s3_um,sgs1_V,sgs2_V,sgs3_V,
//   request1_V,request2_V,request3_V,ao1_V,ao2_V,ao3_V,
//   [truth1_um,truth2_um,truth3_um,interferometer1_um,interferometer2_um,interferometer3_um,]
//   wake_latency_us,compute_us,overrun,limited,held,state,fault_reason,fault_channel,
//   read_status,write_status
// The truth columns are there when the backend has a twin behind it.
//
// Not real-time: the thread allocates, formats and does I/O. It also reports each newly latched
// fault on the events stream (stderr) as it sees it, so the operator learns of it at once.
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "piezoshift/runtime/spsc_ring.hpp"
#include "piezoshift/runtime/telemetry.hpp"

namespace piezoshift::runtime {

struct CsvLoggerOptions {
  std::string path;
  bool with_truth = false;
  double flush_interval_s = 0.25;  //!< write(2) pending whole lines at least this often
  double sync_interval_s = 1.0;    //!< fdatasync at least this often
  std::size_t ring_capacity = std::size_t{1} << 15;  //!< 3.3 s at 10 kHz
  std::FILE* events = stderr;  //!< where newly latched faults are reported (nullptr: nowhere)
};

class CsvLogger {
 public:
  //! Set-up: creates (truncates) the file and writes the header, flushed. Throws core::InputError
  //! naming the file when it cannot be created.
  explicit CsvLogger(CsvLoggerOptions options);
  CsvLogger(const CsvLogger&) = delete;
  CsvLogger& operator=(const CsvLogger&) = delete;
  ~CsvLogger();

  //! The producer side for the loop.
  SpscRing<TelemetryRecord>& ring() noexcept { return ring_; }

  void start();
  //! Drains the ring, writes and syncs everything, closes the file, joins the thread. Idempotent.
  void stop();

  std::uint64_t records_written() const noexcept { return written_.load(); }
  //! Empty when every write succeeded.
  std::string error() const;
  const std::string& path() const noexcept { return options_.path; }

  //! The header line (without newline) for a log with or without the truth columns.
  static std::string header(bool with_truth);
  //! Appends one record as a CSV line (with newline).
  static void format(const TelemetryRecord& r, bool with_truth, std::string& out);

 private:
  void run();
  void drain_into_buffer(std::uint8_t& last_reason);
  bool flush_buffer();

  CsvLoggerOptions options_;
  SpscRing<TelemetryRecord> ring_;
  int fd_ = -1;
  std::string buffer_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> written_{0};
  std::string error_;  // written by the logging thread, read after join
  bool started_ = false;
  bool stopped_ = false;
};

}  // namespace piezoshift::runtime
