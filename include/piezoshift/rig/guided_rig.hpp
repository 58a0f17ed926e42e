#pragma once
// The stage as the guided calibration (guided_calibration.hpp) drives it: poses held by the one
// control tick (runtime/control_cycle.hpp), settling, and one averaging window of the strain
// gauges per reading. BenchRig is the twin through rig::Bench (simulated clock, `--daq
// sim`); LoopRig (loop_rig.hpp) is runtime::ControlLoop in its own real-time thread, the
// operator's prompt in the main one (`--daq comedi:/dev/comediN`, and the twin as `--daq
// sim-rt`). A window's times are on the rig's clock, which is what an interferometer log file is
// matched against.
#include <optional>
#include <string>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/rig/bench.hpp"

namespace piezoshift::rig {

using control::Vec3;

struct RigWindow {
  Vec3 sgs_um{};         //!< mean SGS feedback over the window [um]
  double start_s = 0.0;  //!< on the rig's clock [s]
  double end_s = 0.0;
  bool saturated = false;  //!< a PID sat at its output limit at the window's end
  //! The twin's interferometer, static mode, over this window (BenchRig only).
  std::optional<Vec3> twin_points_um;
};

class GuidedRig {
 public:
  virtual ~GuidedRig() = default;
  //! The controller from the next tick on; std::invalid_argument, the controller unchanged, when
  //! the loop cannot run it (control::params_problem).
  virtual void set_controller(const control::SemiClosedLoopParams& params) = 0;
  virtual control::SemiClosedLoopParams controller() const = 0;
  //! Holds the stage: the PIDs alone on targets S (calibration stage 2).
  virtual void drive_actuators(const Vec3& s_um) = 0;
  //! Holds the stage: the whole controller on Z_d (calibration stage 3).
  virtual void drive_points(const Vec3& zd_um) = 0;
  virtual void settle(double duration_s) = 0;
  //! Open loop at 0 V and settled: the rest position the interferometer is zeroed at.
  virtual void rest(double settle_s) = 0;
  //! One averaging window (the interferometer's static mode, 1 s) of the pose held.
  virtual RigWindow measure() = 0;
  //! The latched supervisor fault, described; empty when none.
  virtual std::string fault() const = 0;
  //! True when the rig is deterministic (the twin): a resumed session re-drives the poses already
  //! recorded, so that the twin is where an uninterrupted session would have left it.
  virtual bool replays() const = 0;
};

class BenchRig final : public GuidedRig {
 public:
  //! window_s: the twin's interferometer averaging window (config.twin.interferometer).
  //! continues: the rig of the stage before, on a bench of its own; this rig's clock starts
  //! where that one's stands, so that window times never repeat within a session (a log file
  //! matched by time needs one time line).
  BenchRig(rig::Bench& bench, double window_s, const BenchRig* continues = nullptr)
      : bench_(bench), window_s_(window_s), continues_(continues) {}
  //! Seconds on this rig's clock.
  double clock_s() const {
    return (continues_ != nullptr ? continues_->clock_s() : 0.0) + bench_.time_s();
  }
  void set_controller(const control::SemiClosedLoopParams& params) override;
  control::SemiClosedLoopParams controller() const override { return bench_.controller_params(); }
  void drive_actuators(const Vec3& s_um) override { bench_.drive_actuators(s_um); }
  void drive_points(const Vec3& zd_um) override { bench_.drive_points(zd_um); }
  void settle(double duration_s) override { bench_.run(duration_s); }
  //! A bench not yet driven is at rest already (nothing is run, so a fresh session's twin is
  //! where `calibrate` on the twin starts its stage 3).
  void rest(double settle_s) override;
  RigWindow measure() override;
  std::string fault() const override;
  bool replays() const override { return true; }

 private:
  rig::Bench& bench_;
  double window_s_;
  const BenchRig* continues_;
};

}  // namespace piezoshift::rig
