#pragma once
// The hold after a measurement (SequenceParams::hold_s, `measure --hold-s`, docs/measure.md)
// summed up from its records: the cavity's path from its set point frame by frame (twin truth:
// path_errors_nm), its RMS, its largest excursion, the RMS of its means over whole seconds, and
// the lock's states. The CLI's report and Python's measure() both print these.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "piezoshift/instrument/sequence.hpp"

namespace piezoshift::instrument {

struct HoldSummary {
  std::size_t frames = 0;
  double span_s = 0.0;  //!< loop time from the first exposure's trigger to the last's
  std::optional<double> frame_interval_s;  //!< span_s / (frames - 1); none under two frames
  //! The cavity's path from its set point at each hold record [nm]; empty without truth
  std::vector<double> path_error_nm;
  //! Their RMS: relative to the sequence's first exposure (frame 0, where the hold returns)
  std::optional<double> path_error_rms_nm;
  std::optional<double> path_error_max_nm;  //!< the largest |path_error_nm|
  //! The RMS of the path's means over the hold's whole seconds (the last, partial second left
  //! out): the drift a lock at the frame rate is there to hold, without the exposure-to-exposure
  //! jitter of the inner loop, which averages out. None without truth or a whole second.
  std::optional<double> path_error_1s_means_rms_nm;
  //! How many hold frames ended in each lock state (ExposureRecord::lock_state); empty unlocked
  std::map<std::string, std::size_t> lock_states;
};

//! The summary of result.hold (all empty and none when there was no hold).
HoldSummary hold_summary(const SequenceResult& result);

}  // namespace piezoshift::instrument
