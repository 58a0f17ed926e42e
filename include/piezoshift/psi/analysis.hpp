#pragma once
// From frames to a surface map, the pipeline `piezoshift psi analyze` runs:
//   wrapped phase (phase_algorithms.hpp) -> masked unwrapping (unwrap.hpp)
//   -> h = phi lambda / (4 pi)  [nm of surface height; Fizeau in reflection]
//   -> piston and tilt (and optionally power) removed (surface_metrics.hpp)
//   -> PV, RMS, PVr and a Zernike fit (zernike.hpp) of the result.
// Pixels whose modulation is below min_modulation_fraction of the pupil's median modulation
// are dropped (NaN) before unwrapping: they carry no phase.
#include <span>
#include <vector>

#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/psi/phase_algorithms.hpp"
#include "piezoshift/psi/surface_metrics.hpp"

namespace piezoshift::psi {

struct AnalysisOptions {
  PhaseOptions phase{};
  double wavelength_nm = core::kHeNeWavelength_nm;
  Removal removal = Removal::kTilt;
  int zernike_terms = 37;
  double min_modulation_fraction = 0.1;
};

struct Analysis {
  PhaseResult phase;
  Map surface_nm;  //!< NaN outside the mask or where the modulation is too low
  Mask valid;      //!< the pixels that hold a value
  SurfaceFigures figures;
  std::vector<double> zernike_nm;  //!< Noll j = 1..zernike_terms, of surface_nm
};

//! The mask's pixels with a finite phase and a modulation of at least min_modulation_fraction of
//! the pupil's median: the pixels that carry a phase. std::invalid_argument when fewer than
//! max(zernike_terms, 36) do (identical, blank or too small frames): the one check of a frame
//! set's fringes, that `psi analyze` and `psi calibrate` share.
Mask modulated_pixels(const PhaseResult& phase, const Mask& mask, const AnalysisOptions& options);

//! std::invalid_argument for wrong frame counts or sizes, or too few valid pixels.
Analysis analyze_frames(std::span<const Map> frames, const Mask& mask,
                        const AnalysisOptions& options);

//! RMS over the common valid pixels of (measured - truth) after removing piston and tilt from
//! the difference [nm].
double surface_error_rms_nm(const Map& measured_nm, const Map& truth_nm, const Mask& mask);

}  // namespace piezoshift::psi
