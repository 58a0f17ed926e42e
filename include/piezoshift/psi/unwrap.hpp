#pragma once
// Masked 2-D phase unwrapping, quality guided: Herraez, Burton, Lalor and Gdeisat 2002,
// "Fast two-dimensional phase-unwrapping algorithm based on sorting by reliability following a
// noncontinuous path", Appl. Opt. 41(35):7437.
//
// Reliability of pixel p with all eight neighbours in the mask, W() wrapping to (-pi, pi]:
//   H  = W(phi(i-1,j) - phi(i,j)) - W(phi(i,j) - phi(i+1,j))       (and V, D1, D2 likewise)
//   D  = sqrt(H^2 + V^2 + D1^2 + D2^2),   R = 1 / D
// pixels on the mask's border (a neighbour missing) get R = 0, so they join last. Each edge
// between two horizontally or vertically adjacent mask pixels has reliability R_p + R_q; edges are
// processed from the most reliable, joining the two pixels' groups with the multiple of 2 pi that
// makes their difference wrapped, the smaller group being shifted. Separate islands of the mask
// are unwrapped independently (each keeps its own 2 pi offset). NaN pixels are treated as outside
// the mask.
#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

//! Unwrapped phase [rad]: NaN outside the mask (or where the input is NaN).
Map unwrap_phase(const Map& wrapped_rad, const Mask& mask);

}  // namespace piezoshift::psi
