#pragma once
// The reference plate's pose, frame by frame, from the Fizeau camera alone (the first piece of
// "calibration from fringes"): fed frames in order, each at a new, unknown pose of the plate
// against a fixed test surface, it returns each frame's piston, tip and tilt relative to the
// first frame, and the displacements of the measurement points P1..P3 (paper, Fig. 7, the
// three points the XL-80 reads for Eq. 8) through the rigid plate (kinematics/tripod.hpp, Eq. 5).
//
// Method: tilt-aware AIA (phase_algorithms.hpp) on the first W frames gives the reference
// phase; every later frame is then located against it, frame k being
//   I_k(x) = A + B cos(Phi(x) + D_k(x)),   D_k = (4 pi / lambda) dz_k,
//   dz_k(x, y) = Z_k + theta_x,k y_m - theta_y,k x_m          (fizeau_simulation.hpp)
//   first window: tilt-aia -> phi_0, delta_k;  phi_ref = sigma_0 phi_0 = Phi + D_0,
//                 D_k - D_0 = sigma_0 delta_k   (sigma_0 = first_direction: frames alone cannot
//                 tell phi from -phi, and tilt-aia takes the mean step positive)
//   kReference (default), each later frame alone: tilt-aware AIA's step (2) with the phase
//                 known, a Gauss-Newton fit of I_k = a + b cos(phi_ref + piston + tip y + tilt x),
//                 piston solved linearly first (no start needed), tip and tilt started from the
//                 plane the two frames before predict (constant velocity);
//   kWindows, tilt-aia on every window of W frames advancing by hop, anchored to phi_ref (not
//                 to the window before, so that errors do not walk):
//                 r(x) = wrap(sigma phi_w - phi_ref - plane_w0)  (plane_w0: its first frame's)
//                 sigma = the sign with the larger coherence |mean exp(i r)|, then a least-squares
//                 plane through r corrects plane_w0, and D_k - D_0 = plane_w0 + sigma delta_k;
//   piston:       temporal unwrapping, p_k = p_k-1 + wrap(p~_k - p_k-1), exact while every true
//                 step is below pi (a quarter wave of mirror motion); tip and tilt need none.
//   output:       Z = lambda p / (4 pi), theta_x = lambda tip / (4 pi R), theta_y = -lambda tilt
//                 / (4 pi R), R the pupil radius on the plate; P1..P3 = tripod.inverse(pose).
// Why: AIA needs no known steps, so the scan may be any motion; the tilt-aware form fits each
// frame's whole plane, the tripod's three degrees of freedom; temporal unwrapping carries the
// fringe order through micrometres of travel with nothing but the frames. kReference because
// tilt-aia on windows of a one-actuator scan (the paper's stage 1) fails: the plate pivots about
// the other legs' line, the pupil near it sees no phase shift, and the window's planes leave
// tilt-aia's range (docs/fizeau.md); one frame against a known phase has neither problem, and
// takes milliseconds instead of seconds.
//
// What it assumes (docs/fizeau.md gives the measured limits):
//   - the test surface is fixed during the scan (the phase it sees moves only with the plate);
//   - the first W frames spread the phase as a PSI sequence does (steps near lambda/8, of
//     piston), since tilt-aia finds the reference from them;
//   - the plate's step between consecutive frames is below a quarter wave of mirror motion at
//     every point of the pupil (pi of phase); refused beyond max_step_rad (default 3/4 of it),
//     and refused when a step differs from the one before by more than max_step_change_rad (an
//     aliased step looks like a reversal); the tilt's change of rate within the fit's reach;
//   - background and modulation uniform over the pupil within a frame (as tilt-aia assumes);
//   - the fringes are resolved: the surface plus the plate's tilt below a fringe per two pixels;
//   - the pupil's centroid on the camera is the plate's origin O (fizeau_simulation.hpp does
//     the same), and plate_m_per_px converts camera pixels to plate metres.
// It says when it cannot: valid = false with the reason (step too large, modulation too low,
// the fit not converged or not matching); after such a frame the fringe order is lost, and
// every later frame is refused too, naming the frame where it was lost. Never a number without
// a valid flag.
//
// Not real-time safe: it allocates, and the first window runs tilt-aia's multi-start fit
// (seconds); docs/fizeau.md gives the time per frame.
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/kinematics/tripod.hpp"
#include "piezoshift/psi/frame_pose.hpp"
#include "piezoshift/psi/grid.hpp"
#include "piezoshift/psi/phase_algorithms.hpp"

namespace piezoshift::psi {

//! How frames after the first window are resolved (see the header comment).
enum class FringeMethod : std::uint8_t {
  kReference,  //!< each frame fitted against the first window's phase: any scan, ms per frame
  kWindows,    //!< tilt-aia on every window: scans whose frames each spread the phase
};

struct FringeTrackerParams {
  FringeMethod method = FringeMethod::kReference;
  int window_frames = 5;  //!< W, frames per tilt-aia fit (at least 3)
  int hop_frames = 0;     //!< kWindows: frames the window advances by, 1..W-1; 0: W - 1
  double wavelength_nm = core::kHeNeWavelength_nm;  //!< HeNe (fizeau_simulation.hpp)
  //! plate metres per camera pixel (FizeauParams: pupil_radius_m / pupil_radius_px)
  double plate_m_per_px = 0.025 / 120.0;
  //! P1..P3 in the plate frame [m] (plant::make_twin_geometry(...).points on the twin)
  std::array<kinematics::PlatePoint, 3> points{};
  //! the sign of the piston's motion over the first window: fringes cannot tell up from down
  int first_direction = +1;
  //! largest phase step between consecutive frames anywhere in the pupil [rad]: 3/4 of the
  //! quarter-wave limit (pi), so that an aliased step up to 1.25 pi is still refused
  double max_step_rad = 0.75 * std::numbers::pi;
  //! largest change of the centre's step from one frame to the next [rad]: an aliased step
  //! (true step s beyond 1.25 pi) reads as the reversal s - 2 pi, caught up to 1.25 pi plus the
  //! step before; as large as max_step_rad, so that a scan may start from rest and stop
  double max_step_change_rad = 0.75 * std::numbers::pi;
  //! the frames' white noise over their modulation (PhaseResult::noise_rms) beyond which the
  //! fringes are too faint to track
  double max_noise_to_modulation = 0.25;
  //! tilt-aia's settings; the tracker sets algorithm, steps_rad and step_tolerance_rad itself
  PhaseOptions phase{};
};

//! Checks ranges; a message naming the field, or empty when valid.
std::string fringe_tracker_problem(const FringeTrackerParams& p);

//! One frame's plate pose relative to frame 0.
struct FringePose {
  std::size_t frame = 0;  //!< index in the order fed, from 0
  bool valid = false;     //!< false: the numbers below are NaN and reason says why
  std::string reason;
  double piston_nm = 0.0;                      //!< Z at the pupil centre (the plate's origin O)
  double theta_x_urad = 0.0;                   //!< tip about x
  double theta_y_urad = 0.0;                   //!< tilt about y
  kinematics::PointDisplacements points_um{};  //!< P1, P2, P3
  //! the fit's white noise over the modulation: the tilt-aia window's (PhaseResult::noise_rms)
  //! for the frames it resolved, the frame's own fit's for a frame fitted alone
  double noise_to_modulation = 0.0;
};

class FringeTracker {
 public:
  //! mask: the pupil on the camera. Throws core::InputError for bad params (the message names
  //! the field), std::invalid_argument for an empty mask or collinear points.
  FringeTracker(const Mask& mask, const FringeTrackerParams& params);

  //! Feeds the next frame (the mask's size, else std::invalid_argument). Returns the frames
  //! resolved by it, in order: none until a window is full, then the window's new frames.
  std::vector<FringePose> push(const Map& frame);

  std::size_t frames_seen() const noexcept { return seen_; }
  //! Where the fringe order was lost ("" while tracking).
  const std::string& lost_reason() const noexcept { return lost_; }

 private:
  using Plane = PhasePlane;
  struct FrameFit {
    Plane plane;
    double noise = 0.0;  // white residual over the modulation
    std::string reason;  // "" when the fit is to be trusted
  };
  std::vector<FringePose> process_window();
  std::vector<FringePose> track_frame(const Map& frame);
  FrameFit fit_frame(const Map& frame, const Plane& start) const;
  std::string anchor(const PhaseResult& r, int& sigma, Plane& w0) const;
  std::string step_problem(std::size_t f, const Plane& prev, const Plane& d) const;
  FringePose pose_of(std::size_t frame, const Plane& d) const;
  std::vector<FringePose> refuse_from(std::size_t first, const std::string& reason);

  Mask mask_;
  FringeTrackerParams p_;
  kinematics::TripodGeometry tripod_;
  //! The pupil's pixels and, once the first window is resolved, Phi + D_0 over them
  PhaseReference ref_;
  bool have_phase_ = false;  //!< ref_.phase_rad holds the first window's phase
  double pupil_radius_m_ = 0.0;
  std::deque<Map> window_;
  std::size_t seen_ = 0;
  std::size_t next_ = 0;             // first frame not yet returned
  std::vector<Plane> planes_;        // D_k - D_0 of every frame returned
  std::optional<double> last_step_;  // the centre's last step [rad]
  std::string lost_;
};

}  // namespace piezoshift::psi
