#pragma once
// The PID gains a procedure holds its poses with, chosen on the plant before the procedure
// excites it. The paper's gains are per sample at 1 ms; re-expressed at another rate
// (10 kHz) they keep the continuous controller they stand for, whose gain reaches up to the
// plate's mode; a heavier or thicker plate brings that mode down to where the gauges see it, and
// the loop rings up at the mode (a 20 mm plate at 10 kHz: +7 % per 2 ms from a 0.3 um step). A
// procedure that ran such gains found out through the supervisor (an oscillation or an SGS jump
// in calibration stage 2). The identified ARX models (loop_identification.hpp) misjudge that
// margin by several dB on such plants (an equation-error fit of a lightly damped mode seen through
// the conditioner), so the loop's stability is measured directly instead, where nothing is at
// risk:
//   ring test   a fresh bench holds the operating point open loop (no PID runs), then the PIDs
//               take over bumplessly with a small step of the targets; the gauges' second
//               difference (the mode's ring, the step's slow response removed) is compared over
//               two windows. The loop holds when the ring decays by at least decay_ratio; it is
//               opened at once, long before the supervisor would act, when the ring grows or a
//               gauge leaves the step by abort_um.
//   gains       the gains asked for, tested at margin_factor times themselves (2: a 6 dB gain
//               margin, which covers the stack's slope rising from 0.75 after a reversal to 1.25
//               at the end of a stroke, 4.4 dB, on the procedure's large moves); if that does not
//               hold, the three gains scaled by step_factor until it does;
//   refusal     when no scale down to min_scale holds, the plant is outside what the procedure
//               can hold: rig::ProcedureFailed saying so.
// "Gauges" above are the loop's feedback: on an oracle bench (RingTestOptions::bench) the plate's
// true position through A, in the gauges' volts.
#include <cstdint>
#include <string>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/rig/bench.hpp"

namespace piezoshift::calibration {

struct RingTestOptions {
  double operating_um = 5.0;  //!< command held open loop, then the gauges' target
  double settle_s = 0.5;      //!< held this long first
  double step_um = 0.5;       //!< added to the targets when the PIDs take over
  double early_s = 0.01;      //!< the first window: [early_s, early_s + window_s) after the step
  double late_s = 0.04;       //!< the second: [late_s, late_s + window_s)
  double window_s = 0.02;
  double decay_ratio = 0.7;  //!< late ring <= decay_ratio x early ring: the loop holds
  //! A ring at the gauges' noise counts as decayed: this many times the second difference's rms
  //! while the open-loop hold settled.
  double noise_factor = 2.0;
  double abort_um = 1.0;  //!< a gauge this far from its target opens the loop at once
  //! The bench's feedback and supervisor: the gauges, or the oracle's plate feedback, whose loop
  //! sees the plate's mode with no stack in between (compare's oracle chooses its gains so).
  rig::BenchOptions bench{};
};

struct RingTest {
  bool holds = false;
  double early_ring_um = 0.0, late_ring_um = 0.0;  //!< rms of the second difference
  double noise_ring_um = 0.0;                      //!< the same over the open-loop hold
  bool aborted = false;                            //!< opened before the second window ended
  //! The ring's frequency as the loop samples it (folded to [0, rate / 2]): Prony's one-mode fit
  //! (mode_identification.hpp) of the loudest gauge's second difference from the step on; 0 when
  //! no oscillation was found.
  double ring_Hz = 0.0;
};

//! The ring test of controller (its gains, sample time, scaling) on a fresh bench (seed).
RingTest ring_test(const config::ProjectConfig& config,
                   const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                   const RingTestOptions& options = {});

struct HoldingGainsOptions {
  RingTestOptions ring{};
  double margin_factor = 2.0;  //!< the gains are tested at this multiple of themselves
  double step_factor = 0.7;    //!< each retry scales the gains by this
  double min_scale = 0.05;     //!< below this the loop is too slow to hold a pose: refused
};

struct HoldingGains {
  control::PidGains gains;  //!< per sample at the controller's rate: what to hold with
  double scale = 1.0;       //!< gains / the gains asked for
  RingTest test;            //!< the last ring test (at margin_factor x gains)
  RingTest first;           //!< the first (at margin_factor x the gains asked): how they rang
  int tests = 0;            //!< ring tests run
};

//! The gains to hold with: controller's own (per sample at its rate) or scaled down, each trial
//! on seed. Throws rig::ProcedureFailed naming `what` when none down to min_scale holds.
HoldingGains holding_gains(const config::ProjectConfig& config,
                           const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                           const HoldingGainsOptions& options, const std::string& what);

}  // namespace piezoshift::calibration
