#pragma once
// Two surface maps of one part compared pixel for pixel (`piezoshift psi compare`, docs/psi.md):
// the difference b - a over the pixels valid in both, its RMS and PV, and the Zernike terms
// (zernike.hpp, Noll) of a, of b and of the difference, all fitted over those common pixels so
// that the difference's terms are b's minus a's.
#include <cstddef>
#include <vector>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

struct SurfaceComparison {
  Map difference_nm;  //!< b - a; NaN where either holds no value
  Mask common;        //!< the pixels valid (finite) in both
  std::size_t pixels = 0;
  double rms_nm = 0.0;               //!< of the difference, about its mean (piston removed)
  double rms_tilt_removed_nm = 0.0;  //!< piston and tilt removed (a Fizeau's alignment)
  double pv_nm = 0.0;                //!< peak to valley of the difference
  std::vector<double> zernike_a_nm;  //!< Noll j = 1..terms
  std::vector<double> zernike_b_nm;
  std::vector<double> zernike_difference_nm;
};

//! std::invalid_argument when the maps' sizes differ or fewer pixels than terms are valid in both.
SurfaceComparison compare_surfaces(const Map& a, const Map& b, int zernike_terms = 37);

}  // namespace piezoshift::psi
