#pragma once
// `piezoshift calibrate --interferometer fizeau`: the paper's three stages with the Fizeau's
// fringes as the interferometer (instrument/fringe_calibration.hpp), on the twin's bench and the
// twin camera, or with --daq on the real-time loop (sim-rt, comedi) and any camera (twin on
// sim-rt, aravis:ID); writes the calibration file `calibrate` writes.
#include <cstdint>
#include <string>

namespace piezoshift::app {

struct FizeauCalibrateRequest {
  std::string out;
  std::string config;                //!< "" built-in defaults; else read with its [camera]
  std::string pid;                   //!< paper or search (stage 1, unchanged)
  std::string controller = "paper";  //!< or improved: its identification around the stages
  std::string camera;                //!< "" or twin, aravis:ID with --daq; files:DIR refused
  std::string surface;    //!< the twin camera's test surface (`psi simulate`'s spec), "" default
  std::string daq;        //!< "" the twin's bench; sim-rt or comedi[:DEVICE]: the real-time loop
  bool free_run = false;  //!< sim-rt: the loop paced by the procedure
  std::string mask;       //!< the pupil as a PNG; "" the twin's scene's, else found in the frames
  std::uint64_t seed = 1;
  bool json = false;
  double max_physics_steps = 0.0;
};

//! Throws core::InputError for what it cannot do (files:DIR, a camera without --daq), and
//! rig::ProcedureFailed, naming the stage and the frame, when a scan fails.
int calibrate_from_fringes_command(const FizeauCalibrateRequest& request);

}  // namespace piezoshift::app
