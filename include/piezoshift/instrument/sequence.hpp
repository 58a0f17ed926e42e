#pragma once
// A phase-shifting sequence through the shipping loop: the stage steps, the camera exposes only
// once the stage has settled, and every frame is stored with the stage's state over its exposure.
//
// The caller owns a ControlLoop in owner mode (LoopConfig::owner_drives) and this thread ticks it
// (on a real-time clock the ticks keep their deadlines; nothing here blocks between two ticks):
//
//   servo on at Z_d = base_um on P1..P3; settle for initial_settle_s
//   for each average a, each frame k:
//     Z_d = base_um + piston_k on P1..P3, piston_k = steps_rad[k] lambda / (4 pi)  (reflection)
//     tick until settled: on every channel the controller's own estimate, the SGS tracking error
//       S - feedback averaged over the last hold_s, within band_nm (OnTarget; never the twin's
//       truth); not settled within timeout_s is a failure, never a frame taken anyway
//     tick until the camera can expose (its readout of the previous frame is over)
//     camera.trigger(t); tick through the exposure, each tick's plate pose to the camera
//       (observe_plate: the twin camera renders from it) and to the exposure's record
//     (TriggerMode::kLine: instead of camera.trigger(t), the loop's trigger pulse is armed once
//       the camera's exposure + readout since the previous edge are over; the exposure's first
//       tick raises the DAQ's line at its scheduled time. The edge reaches the camera as
//       camera.trigger(t_e), t_e = the edge's tick x T (the records' loop time), before that
//       tick's pose: on the twin from the sim backend's record of its line (the wire), on
//       hardware from the loop's report (a line-triggered camera stamps its frame with t_e).
//       Same ticks, same poses, same times as kSoftware.)
//   (with the lock, after each exposure: its frame in and fed to the lock before the next move;
//     on a real-time clock the loop ticks, holding, while the frame's fit runs on the
//     FitThread, fit_thread.hpp)
//   tick, holding the last position, until every frame has arrived (frame_timeout_s)
//   hold_s > 0: the hold. Z_d back to frame 0's; then frame after frame, for hold_s of loop time,
//     as above (settle, expose, the frame): the cavity held where frame 0 of the first average
//     found it, by the lock when there is one, else by the semi-closed loop alone. The hold's
//     frames feed the lock and are not kept (a minute is thousands of frames); their records are.
//   the loop's controlled part ends; tick through its ramp to 0 V
//
// Frames are polled between ticks (lock-free: camera.hpp). A fault the supervisor latches, a
// step that does not settle, a frame lost or late, or a stop signal ends the sequence with
// valid = false and the first reason; the loop still ramps to 0 V. The wall-time floor is
// frames x (settle + exposure + readout), with settle the hold time the criterion needs.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/instrument/fringe_lock_session.hpp"
#include "piezoshift/plant/twin.hpp"
#include "piezoshift/psi/phase_algorithms.hpp"
#include "piezoshift/psi/stage.hpp"
#include "piezoshift/rig/progress.hpp"
#include "piezoshift/rig/validity.hpp"
#include "piezoshift/runtime/control_loop.hpp"

namespace piezoshift::instrument {

//! What starts each exposure: camera.trigger() from this thread, or the loop's pulse on the DAQ's
//! trigger line (the camera's TriggerSource is then a line).
enum class TriggerMode : std::uint8_t { kSoftware, kLine };
//! "software", "line".
const char* to_string(TriggerMode mode) noexcept;

//! The measurements a sequence averages: the one range every front end checks (`measure
//! --averages`, Python's averages, the dashboard's POST /api/measure) and sequence_problem().
inline constexpr int kMinAverages = 1;
inline constexpr int kMaxAverages = 100;

struct SequenceParams {
  std::vector<double> steps_rad;  //!< the phase steps of one measurement, steps_rad[0] = 0
  double wavelength_nm = core::kHeNeWavelength_nm;  //!< HeNe, the usual Fizeau source
  double base_um = 5.0;                             //!< Z_d of P1..P3 at frame 0 (mid travel)
  double initial_settle_s = 0.2;  //!< after the servo closes at the base, before frame 0
  psi::OnTarget on_target{};      //!< the settle criterion (band, hold time, timeout)
  int averages = 1;  //!< measurements taken one after the other, kMinAverages..kMaxAverages
  double frame_timeout_s = 2.0;  //!< after its exposure, for a frame to arrive
  TriggerMode trigger = TriggerMode::kSoftware;
  std::uint32_t trigger_pulse_ticks = 1;  //!< kLine: the pulse's width, 1 to 1000 ticks
  //! The fringe lock (fringe_lock_session.hpp); none: the semi-closed loop alone
  std::optional<LockSetup> lock;
  //! After the averages, the stage held at frame 0's position while the camera exposes frame
  //! after frame for this long [s of loop time]; 0: no hold.
  double hold_s = 0.0;
};

//! The commanded steps of a measurement with algorithm a: given, for lsq, aia and tilt-aia (the
//! algorithms whose steps are free), else k times a's nominal step over its frame count (5 for
//! the free ones). core::InputError naming option for steps a fixed-step algorithm cannot take,
//! or a count the algorithm does not take.
std::vector<double> commanded_steps(psi::Algorithm a, const std::vector<double>& given,
                                    std::string_view option);

//! "" when the sequence stays within the calibrated travel (when known), else why not.
std::string travel_problem(const SequenceParams& p, std::optional<double> travel_z_max_um,
                           std::string_view calibration_source);

//! Why p cannot be run ("" when it can): 3 to 64 steps, finite, the first 0; wavelength, base,
//! times (the hold 0 to 3600 s), averages and pulse width in range.
std::string sequence_problem(const SequenceParams& p);

//! One exposure: what was commanded, when, and where the stage was while the camera integrated.
struct ExposureRecord {
  int average = 0;
  int frame = 0;
  double commanded_step_rad = 0.0;
  double commanded_piston_nm = 0.0;  //!< relative to the base
  double move_time_s = 0.0;          //!< loop time of the move
  double settled_time_s = 0.0;       //!< loop time the criterion was met
  //! Loop time the exposure started (kLine: the edge's tick, on this clock: ticks x T).
  double trigger_time_s = 0.0;
  double exposure_end_s = 0.0;
  //! The controller's estimate over the exposure: per channel the mean of S - feedback; the
  //! largest magnitude of the three, and the largest single-tick magnitude [nm].
  double gauge_error_mean_nm = 0.0;
  double gauge_error_max_nm = 0.0;
  // The twin's truth over the exposure (has_truth), relative to the pose at the base.
  bool has_truth = false;
  double truth_piston_nm = 0.0;  //!< mean piston at the pupil centre
  double truth_blur_nm = 0.0;    //!< its range over the exposure
  double truth_tip_urad = 0.0;   //!< mean theta_x
  double truth_tilt_urad = 0.0;  //!< mean theta_y
  std::uint64_t frame_id = 0;    //!< the frame that arrived for it
  double arrival_wall_s = 0.0;   //!< wall time from the sequence's start to its arrival
  // The fringe lock (SequenceParams::lock), else NaN and "":
  double lock_correction_nm = std::numeric_limits<double>::quiet_NaN();  //!< the move's piston
  double fringe_piston_nm = std::numeric_limits<double>::quiet_NaN();    //!< from the frame
  std::string lock_state;   //!< "reference", or FringeLockState's words after the frame
  std::string lock_reason;  //!< why the frame gave no pose
  int retakes = 0;          //!< tries before this frame whose fringes were lost (LockSetup)
};

struct SequenceResult {
  std::vector<camera::Frame> frames;  //!< averages x steps, in order
  std::vector<ExposureRecord> exposures;
  double loop_time_s = 0.0;  //!< loop time from the first move to the last frame
  double wall_time_s = 0.0;  //!< the same span in wall time
  double floor_s = 0.0;      //!< frames x (hold + exposure + readout)
  std::uint64_t overruns = 0;
  std::uint64_t ticks = 0;
  rig::Validity validity;
  std::optional<LockSummary> lock;   //!< with SequenceParams::lock
  std::vector<ExposureRecord> hold;  //!< the hold's exposures (SequenceParams::hold_s), in order
};

//! The piston that makes frame k's phase step in reflection: steps_rad[k] lambda / (4 pi) [nm].
double step_piston_nm(const SequenceParams& p, std::size_t k);

//! Exposure `index` of the sequence (average after average), as commanded at move_time_s: its
//! average, frame, step and piston; the rest is filled as it is taken.
ExposureRecord planned_exposure(const SequenceParams& p, std::size_t index, double move_time_s);

//! The wall-time floor: frames x (hold_ticks x period + exposure + readout).
double sequence_floor_s(const SequenceParams& p, std::size_t hold_ticks, double period_s,
                        const camera::CameraSettings& settings);

//! A frame polled from camera into result (the next exposure's frame_id and arrival_wall_s, the
//! frame appended): "" when taken, else why the sequence fails (lost, an error, a frame no
//! trigger asked for). Both drivers of a sequence use it (sample_sequence.hpp).
std::string take_frame(camera::FrameStatus status, camera::Frame& frame,
                       const camera::Camera& camera, double arrival_wall_s, SequenceResult& result);

//! The RMS of the cavity's optical path from its set point over exposures first.. (twin: the
//! truth's piston, which carries the cavity's drift, minus the commanded piston, relative to
//! the same at the first exposure: where a lock's reference holds it); nothing without truth or
//! without an exposure from first on.
std::optional<double> path_error_rms_nm(const SequenceResult& result, std::size_t first);

//! The cavity's path from its set point at each of records, as path_error_rms_nm takes it
//! (relative to the sequence's first exposure); empty without truth.
std::vector<double> path_errors_nm(const SequenceResult& result,
                                   const std::vector<ExposureRecord>& records);

//! Runs the sequence (see the header). twin: the twin whose true plate pose feeds the camera and
//! the records (nullptr on hardware). loop must be in owner mode and not started; the DAQ
//! backend must be active. Throws core::InputError for parameters sequence_problem() refuses, and
//! for TriggerMode::kLine on a backend without a trigger line.
SequenceResult run_sequence(runtime::ControlLoop& loop, const plant::Twin* twin,
                            camera::Camera& camera, const SequenceParams& params,
                            const rig::Progress& progress = {});

}  // namespace piezoshift::instrument
