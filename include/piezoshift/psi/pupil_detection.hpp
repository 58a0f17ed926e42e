#pragma once
// The pupil found from the frames' fringe modulation, for frames given without a mask (when
// analysed whole, the unmodulated background pulled AIA's steps 0.47 rad off and the PVr from
// 258 to 305 nm).
//   modulation m(pixel) = the temporal standard deviation of the frames at that pixel
//     (a fringe of amplitude B sampled at steps spread over a period gives 0.6 to 0.75 B; a pixel
//     without fringes, its noise);
//   threshold = fraction x the 99th percentile of m over the frame (a robust maximum: a few hot
//     or saturated pixels do not set it);
//   pupil = the largest 4-connected region above the threshold, with its holes of at most
//     max_hole_fraction of its area filled (dust, a dead pixel); larger holes (a central
//     obstruction) stay outside.
// Refused (std::invalid_argument) when the frames do not change, when the region has fewer than
// min_pixels, when it holds less than min_share of the pixels above the threshold, or when the
// rest of the frame (if it holds 1 % or more) is not at least min_contrast times less modulated
// (medians): then the modulation does not separate a pupil from the background (noise alone
// gives one region 2.6 x above the rest), and a mask is needed. Fringes over the whole frame
// give the whole frame.
#include <cstddef>
#include <span>
#include <vector>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

struct PupilDetection {
  double fraction = 0.25;  //!< of the robust maximum
  double max_hole_fraction = 0.005;
  double min_share = 0.5;
  double min_contrast = 4.0;
  std::size_t min_pixels = 37;  //!< what the analysis needs (analysis.hpp, modulated_pixels)
};

struct DetectedPupil {
  Mask mask;
  double modulation_max = 0.0;  //!< the robust maximum of m [frame units]
  double threshold = 0.0;       //!< [frame units]
  double share = 0.0;           //!< of the pixels above the threshold that are in the region
  //! median m in the pupil over the median outside (infinite when the outside holds < 1 %)
  double contrast = 0.0;
};

DetectedPupil pupil_from_modulation(std::span<const Map> frames, const PupilDetection& d = {});

//! The robust maximum of a modulation map: the 99th percentile of its finite values (a few hot or
//! saturated pixels do not set it); 0 when none is finite.
double robust_max(const std::vector<double>& m);

//! m(pixel), the temporal standard deviation above [frame units], as a map of the frames' size.
//! std::invalid_argument for no frames.
Map modulation_map(std::span<const Map> frames);

}  // namespace piezoshift::psi
