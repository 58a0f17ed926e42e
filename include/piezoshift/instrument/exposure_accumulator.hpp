#pragma once
// The stage's state over one exposure, tick by tick, into its ExposureRecord (sequence.hpp).
// Both drivers of a sequence use it: run_sequence from the ticks it runs, SampleSequence from
// `serve`'s HostSamples (sample_sequence.hpp).
//
//   gauge error   per channel the mean of S - feedback over the exposure's n ticks; the record
//                 keeps the largest magnitude of the three, and the largest single-tick one
//   truth         the mean pose as the camera integrates it: the trajectory is piecewise linear
//                 between the ticks' poses, so the trapezoid rule over the pose at the trigger
//                 and the n ticks' poses, the first and last halved, over n; the piston's range
//                 over the exposure is its blur
#include <array>
#include <cstddef>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/instrument/sequence.hpp"

namespace piezoshift::instrument {

class ExposureAccumulator {
 public:
  //! The pose at the exposure's first instant (the trigger).
  void begin(const camera::PlatePose& first) noexcept;
  //! One tick of the exposure: its S - feedback per channel [nm] and the plate's pose.
  void add(const std::array<double, 3>& error_nm, const camera::PlatePose& pose) noexcept;
  std::size_t ticks() const noexcept { return n_; }
  //! Fills rec's gauge error, exposure_end_s and, with has_truth, its truth.
  void finish(ExposureRecord& rec, bool has_truth, double end_s) const noexcept;

 private:
  std::size_t n_ = 0;
  std::array<double, 3> error_sum_{};
  double error_max_nm_ = 0.0;
  double piston_sum_ = 0.0, tip_sum_ = 0.0, tilt_sum_ = 0.0;
  double lo_ = 0.0, hi_ = 0.0;
  camera::PlatePose last_{};
};

}  // namespace piezoshift::instrument
