#pragma once
// The Zernike chart of a measured surface (io/plot.hpp): its coefficients as bars over the Noll
// index from j = 4, since piston and tilt are removed before the fit and carry nothing. What
// `measure` (zernike.png) and `reproduce`'s measurement (measurement_zernike.png) draw.
#include <span>

#include "piezoshift/io/plot.hpp"

namespace piezoshift::psi {

//! zernike_nm: Noll j = 1.., RMS-normalised [nm]. 800 x 440 pt, SVG and PNG.
io::Figure zernike_figure(std::span<const double> zernike_nm);

}  // namespace piezoshift::psi
