#pragma once
// The simulated lab bench: the digital twin driven by the paper's controller exactly as the
// xPC target drives the hardware (paper, Section 4, Figures 8 and 9). One control tick:
//   sgs_V  = twin.read_ai()                  the AI sample taken at the end of the last period
//   out    = controller(setpoint, sgs_V)     one SemiClosedLoopController tick
//   twin.step(out.dac_V)                     AO written and held for one period of physics
// so the controller sees y(k+1) from u(k): one period of delay, as in a read-compute-write loop.
//
// Three ways to drive it, as the paper's procedures need:
//   drive_points(Z_d)       the full controller (feedforward p, A and the three PIDs)
//   drive_actuators(S)      the inner loops alone (calibration stages 1 and 2)
//   drive_open_loop(V)      DAQ volts straight to the amplifiers (travel range, open loop)
// Switching from open loop to a closed loop hands over bumplessly (the PIDs start from the
// command already applied).
//
// The interferometer is read in its static mode by measure_static(): the next full 1 s averaging
// window (paper, Section 4.2), with the mean SGS feedback over the same window.
//
// Not real-time: it is the engine of offline calibration and experiments, stepping as fast as
// the twin allows.
#include <cstdint>
#include <functional>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/io/project_config.hpp"
#include "piezoshift/plant/twin.hpp"

namespace piezoshift::experiments {

using control::Vec3;

enum class DriveMode : std::uint8_t { kOpenLoop, kActuators, kPoints };

struct StaticMeasurement {
  Vec3 points_um{};  //!< interferometer, static mode: mean over one window, P1..P3 [um]
  Vec3 sgs_um{};     //!< SGS feedback averaged over the same window [um]
  double window_end_s = 0.0;
};

class Bench {
 public:
  //! Throws std::invalid_argument when the configuration cannot make a twin.
  Bench(const io::ProjectConfig& config, const control::SemiClosedLoopParams& controller,
        std::uint64_t seed);

  //! Replaces the controller's parameters; the PIDs restart from the present commands.
  void set_controller(const control::SemiClosedLoopParams& params);
  const control::SemiClosedLoopParams& controller_params() const { return controller_.params(); }

  void drive_open_loop(const Vec3& ao_V);
  void drive_actuators(const Vec3& target_um);
  void drive_points(const Vec3& zd_um);

  //! Runs whole control ticks for duration_s (rounded to the nearest tick, at least one);
  //! on_tick, when given, is called after every tick.
  void run(double duration_s, const std::function<void(const Bench&)>& on_tick = {});
  //! Runs until the interferometer has completed a static window that began after this call,
  //! and returns it (between 1 and 2 static windows of simulated time).
  StaticMeasurement measure_static();

  const plant::Twin& twin() const { return twin_; }
  plant::Twin& twin() { return twin_; }
  const control::ControllerOutput& last_output() const { return out_; }
  DriveMode mode() const { return mode_; }
  double time_s() const { return twin_.time_s(); }
  double sample_time_s() const { return sample_time_s_; }
  std::uint64_t ticks() const { return twin_.ticks(); }

 private:
  void tick();
  Vec3 present_command_um() const;

  plant::Twin twin_;
  control::SemiClosedLoopController controller_;
  double sample_time_s_;
  DriveMode mode_ = DriveMode::kOpenLoop;
  Vec3 setpoint_{};  // V, S or Z_d according to mode_
  control::ControllerOutput out_{};
};

}  // namespace piezoshift::experiments
