#pragma once
// The phase shifter as the PSI acquisition sees it: move, wait until on target, expose. A real
// DAQ variant implements the same three calls; BenchStage drives the simulated bench
// (rig/bench.hpp) with the paper's controller.
//
// BenchStage:
//   move(piston_nm)          drive_points(Z_d) with Z_d = base_um + piston_nm / 1000 on P1..P3
//                            (equal point displacements: a pure piston of the plate)
//   wait_on_target(band)     runs ticks until every channel's gauge error (target S minus
//                            feedback, in the controller's nominal micrometres), averaged over
//                            the last hold_s, is within band_nm, as a controller's on-target
//                            flag would: judged on what the hardware sees, never on the twin's
//                            truth (averaged, because single samples carry the gauges' noise)
//   expose(T)                runs the ticks of the exposure and returns the TRUE plate pose
//                            (twin().fringe_piston_nm(): plate_z_um, plus the cavity's drift
//                            when twin.cavity.in_fringes; truth() theta_x_urad, theta_y_urad;
//                            relative to the pose at construction) at its start and after
//                            every tick
// Every tick is also appended to log() (time, commanded piston, mean gauge error, true pose).
#include <vector>

#include "piezoshift/psi/fizeau_simulation.hpp"

namespace piezoshift::rig {
class Bench;
}

namespace piezoshift::psi {

struct OnTarget {
  double band_nm = 2.0;    //!< |mean(S - feedback)| over hold_s on every channel
  double hold_s = 0.005;   //!< for this long (5 ticks at 1 kHz)
  double timeout_s = 1.0;  //!< give up (the frame is then taken anyway and flagged)
};

struct StageLogEntry {
  double time_s = 0.0;
  double command_nm = 0.0;      //!< commanded piston, relative to the base
  double gauge_error_nm = 0.0;  //!< largest |S - feedback| of the three channels
  PoseSample truth;             //!< the plate's true pose
};

class Stage {
 public:
  virtual ~Stage() = default;
  virtual void move(double piston_nm) = 0;
  //! True when on target; false at the timeout.
  virtual bool wait_on_target(const OnTarget& criterion) = 0;
  //! The true pose trajectory of one exposure (at least two samples).
  virtual std::vector<PoseSample> expose(double exposure_s) = 0;
  virtual double time_s() const = 0;
  virtual const std::vector<StageLogEntry>& log() const = 0;
};

class BenchStage final : public Stage {
 public:
  //! Drives the bench to base_um on all points (the reference position, mid travel) and lets it
  //! settle for settle_s; poses are reported relative to the pose reached then.
  BenchStage(rig::Bench& bench, double base_um = 5.0, double settle_s = 0.5);
  void move(double piston_nm) override;
  bool wait_on_target(const OnTarget& criterion) override;
  std::vector<PoseSample> expose(double exposure_s) override;
  double time_s() const override;
  const std::vector<StageLogEntry>& log() const override { return log_; }

 private:
  PoseSample pose() const;
  void tick();

  rig::Bench& bench_;
  double base_um_;
  double command_nm_ = 0.0;
  PoseSample origin_{};
  std::vector<StageLogEntry> log_;
};

}  // namespace piezoshift::psi
