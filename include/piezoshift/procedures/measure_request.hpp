#pragma once
// One phase-shifting measurement as a user asks for it (docs/measure.md): `piezoshift measure`
// parses its options into a MeasureRequest, Python's piezoshift.measure() its arguments; both run
// it with run_measure (measure_run.hpp) and print or return its outcome through measure_json
// (measure_json.hpp). validate() is the one check of the request's values that needs no file;
// run_measure checks the rest (the configuration, the calibration, the camera) in the order it
// needs them.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/instrument/fringe_lock_session.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/plant/simulation_cost.hpp"
#include "piezoshift/psi/grid.hpp"
#include "piezoshift/psi/stage.hpp"

namespace piezoshift::procedures {

//! Whose names a refusal uses: the CLI's options (--averages) or Python's arguments (averages).
enum class MeasureCaller : std::uint8_t { kCli, kPython };

struct MeasureRequest {
  MeasureCaller caller = MeasureCaller::kCli;
  std::string camera = "twin";  //!< twin, files:DIR or aravis:ID (docs/camera.md)
  std::string daq = "sim";      //!< sim, or comedi:/dev/comediN (Python: sim)
  double rate_Hz = 1000.0;      //!< the loop's: the paper's 1 kHz (check_loop_rate)
  std::string config_file;      //!< "" the built-in configuration
  //! A calibration file; "" and no controller: the twin calibrated first (resolve_calibration).
  std::string calibration_file;
  std::optional<control::SemiClosedLoopParams> controller;  //!< Python: a controller instead
  std::string algorithm = "hariharan5";
  std::vector<double> steps_rad;  //!< commanded steps; empty: the algorithm's
  int averages = 1;               //!< in instrument::kAveragesRange
  std::string surface;            //!< the twin camera's test surface (psi simulate's spec)
  std::string mask_file;          //!< the CLI's pupil: a PNG ("" none)
  std::optional<psi::Mask> mask;  //!< Python's pupil: an array (its size checked here)
  double base_um = instrument::SequenceParams{}.base_um;
  psi::OnTarget on_target{};
  double frame_timeout_s = instrument::SequenceParams{}.frame_timeout_s;
  std::uint64_t seed = 1;  //!< the twin's and the camera's noise
  bool free_run = false;   //!< sim only: a simulated clock (Python: always)
  std::string trigger = "software";
  std::string trigger_line;  //!< comedi: SUBDEVICE/CHANNEL of the trigger output
  int cpu = -1;              //!< the loop's CPU (-1 the last one, -2 none)
  bool lock = false;         //!< the fringe lock (docs/fizeau.md)
  double lock_retake_s = instrument::LockSetup{}.retake_s;
  double hold_s = instrument::SequenceParams{}.hold_s;
  double max_physics_steps = plant::kDefaultPhysicsStepBudget;  //!< the start-up calibration's
  //! The CLI's --out: required there, checked (absent or an empty folder) before anything runs.
  std::string out;
};

//! Aravis's in-process fake camera on the twin: shown the twin's fringes (twin_fed_camera.hpp).
bool fed_by_twin(const MeasureRequest& r);

//! The front end's name for an option: "--averages" (CLI) or "averages" (Python).
std::string option_name(const MeasureRequest& r, std::string_view cli, std::string_view python);

//! Throws core::InputError naming the option at fault: the loop rate, the trigger, --out, the
//! camera against the DAQ, --surface and --mask against the camera.
void validate(const MeasureRequest& r);

//! Refuses (InputError) an --out that exists and is not an empty folder: called before the
//! measurement, and again when it is written.
void check_measure_out(const std::string& out);

}  // namespace piezoshift::procedures
