#pragma once
// The simulated lab bench: the digital twin as the `sim` DAQ backend (runtime/sim_backend.hpp),
// closed by the loop every command ships (runtime/control_loop.hpp, in owner mode: DAQ read,
// controller, safety supervisor, DAQ write, with the backends' timing contract), on a simulated
// clock: tick k runs at k T_s and is never late, so the bench steps as fast as the twin allows.
// It is the engine of the offline calibration procedures and of the paper's experiments, so every
// figure piezoshift reports comes from the loop `run` and `serve` run.
//
// Three ways to drive it, as the paper's procedures need:
//   drive_points(Z_d)       the full controller (feedforward p, A and the three PIDs)
//   drive_actuators(S)      the inner loops alone (calibration stages 1 and 2)
//   drive_open_loop(V)      DAQ volts straight to the amplifiers (travel range, open loop)
// Switching from open loop to a closed loop hands over bumplessly (the PIDs start from the
// command already applied). The supervisor is always there: a fault it latches ramps the outputs
// to 0 V and stays latched (faulted(), fault()); the procedures and experiments report it.
//
// Feedback: the stacks' strain gauges (kGauges, what hardware has), or the oracle (kOracle,
// runtime/oracle_backend.hpp: the plate's true point displacements through the calibrated A,
// impossible on hardware, the floor of any gauge-fed controller).
//
// The interferometer is read in its static mode by measure_static(): the next full 1 s averaging
// window (paper, Section 4.2), with the mean SGS feedback over the same window.
#include <cstdint>
#include <functional>
#include <memory>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/notch_filter.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/plant/twin.hpp"
#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/oracle_backend.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

namespace piezoshift::rig {

using control::Vec3;
using runtime::DriveMode;

enum class Feedback : std::uint8_t {
  kGauges,  //!< the stacks' strain gauges (the paper's semi-closed loop)
  kOracle,  //!< the plate's true point displacements (impossible on hardware)
};
const char* to_string(Feedback feedback) noexcept;

struct BenchOptions {
  Feedback feedback = Feedback::kGauges;
  runtime::SafetyLimits limits{};  //!< the supervisor's, as `run` and `serve` use by default
  //! The oracle's feedback notches (runtime/oracle_backend.hpp); none by default. Not for kGauges.
  control::OracleNotches oracle_notch{};
};

struct StaticMeasurement {
  Vec3 points_um{};  //!< interferometer, static mode: mean over one window, P1..P3 [um]
  Vec3 sgs_um{};     //!< SGS feedback averaged over the same window [um]
  double window_end_s = 0.0;
};

class Bench {
 public:
  //! Throws std::invalid_argument when the configuration cannot make a twin or the controller's
  //! sample time is not the DAQ's period.
  Bench(const config::ProjectConfig& config, const control::SemiClosedLoopParams& controller,
        std::uint64_t seed, const BenchOptions& options = {});
  ~Bench();
  Bench(const Bench&) = delete;
  Bench& operator=(const Bench&) = delete;

  //! Replaces the controller's parameters; the PIDs restart from the present commands.
  void set_controller(const control::SemiClosedLoopParams& params);
  const control::SemiClosedLoopParams& controller_params() const {
    return loop_->controller().params();
  }

  void drive_open_loop(const Vec3& ao_V);
  void drive_actuators(const Vec3& target_um);
  void drive_points(const Vec3& zd_um);

  //! Runs whole control ticks for duration_s (rounded to the nearest tick, at least one);
  //! on_tick, when given, is called after every tick.
  void run(double duration_s, const std::function<void(const Bench&)>& on_tick = {});
  //! Runs until the interferometer has completed a static window that began after this call,
  //! and returns it (between 1 and 2 static windows of simulated time).
  StaticMeasurement measure_static();

  const plant::Twin& twin() const { return sim_->twin(); }
  const control::ControllerOutput& last_output() const { return loop_->last_cycle().controller; }
  //! The last tick as a whole: AI, controller, supervisor (ao_V is what went out), statuses.
  const runtime::CycleSample& last_cycle() const { return loop_->last_cycle(); }
  DriveMode mode() const { return loop_->mode(); }
  Feedback feedback() const { return options_.feedback; }
  bool faulted() const { return loop_->supervisor().faulted(); }
  //! The latched fault (reason kNone when none).
  const runtime::FaultRecord& fault() const { return loop_->supervisor().fault(); }
  double time_s() const { return sim_->twin().time_s(); }
  double sample_time_s() const { return sample_time_s_; }
  std::uint64_t ticks() const { return loop_->ticks(); }

 private:
  void tick();

  BenchOptions options_;
  double sample_time_s_;
  std::uint64_t steps_per_tick_;  // the twin's physics steps per control tick
  std::unique_ptr<runtime::SimBackend> sim_;
  std::unique_ptr<runtime::OracleBackend> oracle_;
  runtime::DaqBackend* daq_ = nullptr;
  runtime::SimulatedClock clock_;
  std::unique_ptr<runtime::ControlLoop> loop_;
};

}  // namespace piezoshift::rig
