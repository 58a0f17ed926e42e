#pragma once
// The inner loop's plant as the PID sees it, identified on the bench through the shipping tick
// (rig/bench.hpp), so that its model carries the tick's real delays: from the PID's
// output u (um of command, control/signal_scaling.hpp) to the SGS feedback y (um), per actuator,
// at the loop's sample time, as an ARX model
//   y_k = a_1 y_{k-1} + ... + a_na y_{k-na} + b_1 u_{k-1} + ... + b_nb u_{k-nb} + c
// (u_k is what tick k writes after reading y_k, so u reaches y one tick later at the earliest; c
// takes the operating point's offset). Fitted by least squares to the response to a
// pseudo-random binary sequence (PRBS) of small amplitude around an operating point the PIDs
// first hold, the three channels excited at once by independent sequences (the plate couples the
// legs a little; that coupling is left in the residual).
//
// Small-signal, at one operating point: a piezo stack's gain depends on amplitude and history
// (hysteresis), which is why the amplitude is a phase step's size by default.
#include <array>
#include <complex>
#include <cstdint>
#include <span>
#include <vector>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/runtime/stability_margins.hpp"

namespace piezoshift::calibration {

struct ArxModel {
  double sample_time_s = 1e-3;
  std::vector<double> a;  //!< a_1 .. a_na
  std::vector<double> b;  //!< b_1 .. b_nb
  double c = 0.0;
  double rms_residual_um = 0.0;  //!< of the one-step prediction on the fitted data

  //! P(e^{j 2 pi f T}) = (sum b_j z^-j) / (1 - sum a_i z^-i).
  std::complex<double> frequency_response(double frequency_Hz) const;
  double dc_gain() const;  //!< P(1)
  //! y_k from y_{k-1..k-na} (newest first) and u_{k-1..k-nb} (newest first), with the offset c.
  double predict(std::span<const double> y_past, std::span<const double> u_past) const;
};

//! Least squares on recorded series (u_k written at tick k, y_k read at tick k). Throws FitError
//! (fit_error.hpp) when the series differ in length, hold a non-finite value, are too short for
//! the orders (at least 10 rows per unknown) or do not excite the model (rank-deficient).
ArxModel fit_arx(std::span<const double> u, std::span<const double> y, int na, int nb,
                 double sample_time_s);

struct LoopIdentificationOptions {
  double operating_um = 5.0;   //!< SGS target the PIDs hold before the excitation
  double settle_s = 1.0;       //!< held this long first
  double amplitude_um = 0.08;  //!< PRBS +-amplitude of command around the held command
  double duration_s = 2.0;     //!< of the excitation
  int hold_ticks = 2;          //!< shortest PRBS level, in ticks (its bandwidth: fs / (2 hold))
  int na = 3;
  int nb = 4;
};

struct LoopIdentification {
  std::array<ArxModel, 3> channel;
  std::array<double, 3> operating_command_um{};  //!< the PIDs' u where the excitation began
};

//! On a fresh bench with `controller` (its scaling and sample time; its PIDs hold the operating
//! point, then the loop is opened). Throws rig::ProcedureFailed when the supervisor trips.
LoopIdentification identify_loop(const config::ProjectConfig& config,
                                 const control::SemiClosedLoopParams& controller,
                                 std::uint64_t seed, const LoopIdentificationOptions& options = {});

//! L = C P at frequency_Hz: the PID (per-sample gains at the model's sample time) times the model.
std::complex<double> loop_frequency_response(const ArxModel& plant, const control::PidParams& pid,
                                             double frequency_Hz);

//! The margins of each channel's loop: the PID (per-sample gains at the models' sample time)
//! times its identified plant, from 0.01 Hz to Nyquist.
std::array<runtime::StabilityMargins, 3> pid_margins(const LoopIdentification& plant,
                                                     const control::PidParams& pid);

//! The improved controller's correction loop (control/semi_closed_loop.hpp) on the identified
//! plant: c integrates the error with ki per sample and reaches the command through the model's
//! inverse, whose small-signal gain is 1 / w0 (the linear weight: the smallest slope, so the
//! largest loop gain), so L = ki / (1 - z^-1) P / w0 per channel. Evaluated at ki the hold's gain
//! and at ki_max the boost's ceiling; the plant's models must be at the improved controller's
//! sample time.
std::array<runtime::StabilityMargins, 3> correction_margins(const LoopIdentification& plant,
                                                            const control::ImprovedParams& improved,
                                                            double ki);

}  // namespace piezoshift::calibration
