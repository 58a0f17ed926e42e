#pragma once
// The data recorder's trigger as PI's GCS 2.0 DRT models it (docs/gcs.md, "Data recorder"):
// which commands restart the recording from point 1, and from which sample on. One trigger
// serves every table (they share one clock).
//
//   source 0, 1   any command that changes the position (MOV, MVR, SVA, SVO, STP, #24, WGO
//                 starting a generator): motion()
//          2      the next command line of any kind (a query too), then 0 again: line_done()
//          4      immediately, at the DRT itself; motion commands do not restart it
//   WGR           restarts it whatever the source: restart()
// A restart names the sequence number of the command that caused it, and the recording takes
// only samples whose tick applied that command (records()), so point 1 is the tick the command
// took effect in, not a tick from before it reached the loop.
// Not thread-safe: the server's one network thread owns it.
#include <cstdint>
#include <string_view>

#include "piezoshift/host/data_recorder.hpp"

namespace piezoshift::host {

class RecordTrigger {
 public:
  explicit RecordTrigger(DataRecorder& recorder) : recorder_(recorder) {}

  //! A source DRT accepts: 0, 1, 2, 4.
  static bool is_source(long long source) noexcept {
    return source == 0 || source == 1 || source == 2 || source == 4;
  }
  //! DRT (source is_source); source 4 restarts the recording at `sequence`, the last command
  //! sent.
  void set_source(int source, std::uint64_t sequence);
  int source() const noexcept { return source_; }

  //! A motion command sent as `sequence`: restarts with source 0 and 1.
  void motion(std::uint64_t sequence);
  //! A command line `name` handled, `sequence` the last command sent: source 2 restarts and
  //! becomes 0 again (not for DRT, which has just set it).
  void line_done(std::string_view name, std::uint64_t sequence);
  //! Recording from point 1 again, from the samples that applied command `sequence`.
  void restart(std::uint64_t sequence);
  //! Whether a sample that applied command `applied_sequence` belongs to the recording.
  bool records(std::uint64_t applied_sequence) const noexcept {
    return applied_sequence >= from_sequence_;
  }

 private:
  DataRecorder& recorder_;
  int source_ = 0;
  std::uint64_t from_sequence_ = 0;
};

}  // namespace piezoshift::host
