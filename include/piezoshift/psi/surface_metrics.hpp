#pragma once
// Figures of a measured surface over the pupil (finite pixels within the mask):
//   PV  = max - min,   RMS = sqrt(mean((h - mean h)^2))
//   PVr = PV(sum_{j=1..36} c_j Z_j) + 3 RMS(h - sum_{j=1..36} c_j Z_j)      (Evans 2009, "PVr: a
//         robust amplitude parameter for optical surface specification", Opt. Eng. 48(4):043605)
// and removal of the alignment terms a Fizeau cannot tell from the surface: piston (Z1), tilt
// (Z2, Z3) and, where asked, power (Z4), each by a least-squares Zernike fit over the pupil.
#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

enum class Removal {
  kPiston,        //!< Z1
  kTilt,          //!< Z1..Z3
  kTiltAndPower,  //!< Z1..Z4
};

//! surface minus its least-squares fit of the removed terms (NaN outside the mask kept).
Map remove_terms(const Map& surface, const Mask& mask, Removal removal);

struct SurfaceFigures {
  double pv = 0.0;   //!< peak to valley, surface units
  double rms = 0.0;  //!< about the mean
  double pvr = 0.0;  //!< Evans' PVr (36 Zernike terms)
  std::size_t pixels = 0;
};

//! PV and RMS (and PVr when with_pvr). std::invalid_argument for no finite pixel in the mask.
SurfaceFigures surface_figures(const Map& surface, const Mask& mask, bool with_pvr = true);

}  // namespace piezoshift::psi
