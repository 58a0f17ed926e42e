#pragma once
// The fringe visibility of one frame, for the live view (a single frame has no temporal
// modulation: pupil_detection.hpp's needs phase-shifted frames). The frame is cut into square
// tiles of tile_px; in each tile
//
//   V = (I_hi - I_lo) / (I_hi + I_lo),  I_hi, I_lo the 98th and 2nd percentiles of its counts
//
// (percentiles, not max and min, so that shot noise and a hot pixel do not inflate it). A tile
// needs at least one fringe period across it to show its full visibility; a tile whose I_hi + I_lo
// is below dark_fraction of full scale is too dark to judge (outside the pupil) and left NaN.
// V = 1 for fringes from black to the peak; a uniform (unmodulated) tile gives its noise, ~0.
#include <cstddef>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

struct FringeVisibility {
  Map tiles;               //!< V per tile (NaN: too dark), tiles across x tiles down
  std::size_t judged = 0;  //!< tiles not too dark
  double median = 0.0;     //!< over the judged tiles (NaN when none)
  double p90 = 0.0;        //!< 90th percentile: the best-fringed part of the pupil
};

//! counts: one frame; full_scale_counts: 2^bits - 1. std::invalid_argument for tile_px < 2 or
//! an empty frame.
FringeVisibility fringe_visibility(const Map& counts, double full_scale_counts, int tile_px = 32,
                                   double dark_fraction = 0.04);

}  // namespace piezoshift::psi
