#pragma once
// The calibration's real-time loop on a bench (`calibrate --daq comedi:/dev/comediN|sim-rt`, the
// guided calibration and the calibration from fringes alike): the loop stack (loop_stack.hpp)
// with the twin at seed + 1 on sim-rt, and rig::LoopRig running the loop in a thread of its own,
// Ctrl-C (SIGINT, SIGTERM) ramping the stage to 0 V. Says once on stderr what real-time
// treatment the loop was refused.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "piezoshift/procedures/loop_setup.hpp"
#include "piezoshift/procedures/loop_stack.hpp"
#include "piezoshift/rig/loop_rig.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::procedures {

struct LoopRigStackOptions {
  std::string daq;          //!< sim-rt or comedi[:DEVICE]
  bool free_run = false;    //!< sim-rt: paced by the procedure
  std::uint64_t seed = 1;   //!< the twin's is seed + 1 (stage 2's, as on the bench)
  std::string config_path;  //!< for messages
  double window_s = 1.0;    //!< the interferometer's static window (the guided readings)
};

class LoopRigStack {
 public:
  //! Throws core::InputError naming a device it cannot open.
  LoopRigStack(const LoopRigStackOptions& options, const runtime::InstallationConfig& installation,
               const control::SemiClosedLoopParams& base);
  rig::LoopRig& rig() { return *rig_; }
  //! The twin when --daq sim-rt, else null.
  runtime::SimBackend* sim() { return stack_->sim(); }

 private:
  std::optional<StopSignals> signals_;  // outlives the loop: Ctrl-C during its ramp is harmless
  std::unique_ptr<LoopStack> stack_;
  std::unique_ptr<rig::LoopRig> rig_;
};

}  // namespace piezoshift::procedures
