#pragma once
// `piezoshift calibrate --interferometer fizeau --camera twin`: the paper's three stages with the
// Fizeau's fringes as the interferometer (instrument/fringe_calibration.hpp), on the twin's
// bench and the twin camera; writes the calibration file `calibrate` writes.
#include <cstdint>
#include <string>

namespace piezoshift::app {

struct FizeauCalibrateRequest {
  std::string out;
  std::string config;                //!< "" built-in defaults; else read with its [camera]
  std::string pid;                   //!< paper or search (stage 1, unchanged)
  std::string controller = "paper";  //!< or improved: its identification around the stages
  std::string camera;                //!< "" or twin; anything else refused
  std::string surface;  //!< the twin camera's test surface (`psi simulate`'s spec), "" default
  std::uint64_t seed = 1;
  bool json = false;
  double max_physics_steps = 0.0;
};

//! Throws core::InputError for what it cannot do (a camera other than the twin), and
//! rig::ProcedureFailed, naming the stage and the frame, when a scan fails.
int calibrate_from_fringes_command(const FizeauCalibrateRequest& request);

}  // namespace piezoshift::app
