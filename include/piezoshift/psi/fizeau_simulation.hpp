#pragma once
// Fizeau interferograms of a test surface against the reference flat carried by the phase
// shifter's plate, rendered with the plate's real motion during each exposure.
//
// Height difference at pupil point (x, y) (pupil coordinates, grid.hpp; x_m = x R_pupil):
//   h(x, y, t) = s(x, y) + dz(x, y, t),   dz = Z(t) + theta_x(t) y_m - theta_y(t) x_m
// (the plate's rigid-body displacement, kinematics/tripod.hpp), phase 4 pi h / lambda, so a plate
// step of lambda/8 is a pi/2 phase step. The camera integrates over the exposure:
//   e(x, y) = N_e [1 + V (1/T) int_0^T cos(4 pi h(x, y, t) / lambda) dt]
// the integral taken over the piecewise-linear pose trajectory between the supplied samples (the
// twin's 1 kHz ticks), `subsamples` midpoints per interval. Then shot noise (Gaussian with
// variance e, the Poisson limit), read noise, and quantisation to the bit depth over the full
// well:  counts = round(clip(e + noise, 0, full well) / full well * (2^bits - 1)).
//
// Test surface: a sum of Noll Zernike terms (zernike.hpp, coefficients = RMS of each term in nm)
// plus optional roughness: white Gaussian noise smoothed by a box filter of correlation_px,
// scaled to roughness_rms_nm over the pupil.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

struct SurfaceSpec {
  std::vector<std::pair<int, double>> zernike_nm{{4, 40.0}, {5, 25.0}, {6, -15.0}, {7, 10.0},
                                                 {8, -8.0}, {9, 5.0},  {11, 12.0}};
  double roughness_rms_nm = 0.5;
  int roughness_correlation_px = 3;
};

//! The largest test surface [nm RMS], of one term and of all terms together: about 3 waves RMS
//! at 632.8 nm, the range of a Fizeau (docs/psi.md, "Test surfaces"). Z4 at this bound slopes
//! 115 nm per pixel at the edge of the default 120 px pupil, below the lambda/4 = 158 nm
//! (pi of phase in reflection) that leaves fringes resolvable.
inline constexpr double kMaxSurfaceTermNm = 2000.0;
//! Roughness [nm RMS]: lambda/12 at 632.8 nm, adjacent pixels still within pi of phase.
inline constexpr double kMaxRoughnessRmsNm = 50.0;

//! "Z4=40,Z5=25,rough=0.5" (Noll index = nm; rough = nm RMS; "flat" for none). Throws
//! core::InputError naming the spec and the offending item, and refuses terms, or all terms
//! together, beyond kMaxSurfaceTermNm and roughness beyond kMaxRoughnessRmsNm.
SurfaceSpec parse_surface_spec(std::string_view spec);
//! The surface [nm] over the mask (NaN outside). Roughness draws from rng.
Map make_surface_nm(const SurfaceSpec& spec, const Mask& mask, plant::Rng& rng);

struct FizeauParams {
  int width_px = 256;
  int height_px = 256;
  double pupil_radius_px = 120.0;  //!< the pupil on the camera
  double pupil_radius_m = 0.025;   //!< on the plate: a 50 mm aperture (assumed; not in the paper)
  double wavelength_nm = core::kHeNeWavelength_nm;  //!< HeNe, the usual Fizeau source
  int subsamples = 4;                               //!< integration points per pose interval
};

struct CameraParams {
  double exposure_s = 1e-3;      //!< a 1 ms exposure
  double full_well_e = 20000.0;  //!< typical CCD/CMOS machine-vision sensor
  double mean_fill = 0.45;       //!< mean signal as a fraction of the full well
  double visibility = 0.9;       //!< V = B / A
  double read_noise_e = 10.0;    //!< rms electrons
  bool shot_noise = true;
  int bit_depth = 12;  //!< 8..16
};

//! Checks ranges; returns a message naming the field, or empty when valid.
std::string fizeau_problem(const FizeauParams& f);
std::string camera_problem(const CameraParams& c);

//! Plate pose at one instant, relative to the reference position.
struct PoseSample {
  double time_s = 0.0;
  double piston_nm = 0.0;     //!< Z at the pupil centre
  double theta_x_urad = 0.0;  //!< tip about x
  double theta_y_urad = 0.0;  //!< tilt about y
};

//! One camera frame [counts] from the pose samples of its exposure (at least one; one sample:
//! a frozen plate). NaN-free: outside the mask the background level is rendered.
Map render_frame(const Map& surface_nm, const Mask& mask, const FizeauParams& fizeau,
                 const CameraParams& camera, std::span<const PoseSample> exposure, plant::Rng& rng);

}  // namespace piezoshift::psi
