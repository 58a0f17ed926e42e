#pragma once
// The digital twin of the whole phase-shifter hardware chain (paper, Sections 2 and 4):
//
//   DAQ AO (16 bit, held) -> amplifier x15 (bandwidth, current limit, 0..150 V)
//     -> stack: hysteresis + creep -> free elongation -> stack spring + ball contact
//     -> mechanism springs and masses, rigid plate (exact modal discretization)
//     -> plate pose, points P1..P3 -> interferometer (noise, resolution, drift)
//   stack elongation -> SGS conditioner (gain, nonlinearity, filter, noise, drift) -> DAQ AI
//
// Stepping (one control period T_s per advance()):
//   write_ao(v)   the three AO volts, quantized, held from now on
//   advance()     T_s of physics in substeps of h = 1 / physics_rate_Hz, then one AI sample
//   read_ai()     the AI volts sampled at the end of the last advance()
// These are the plant's own steps, not a way to close a loop: the loop closes through the `sim`
// DAQ backend (runtime/sim_backend.hpp), which orders them by the one timing contract every
// backend keeps (runtime/daq_backend.hpp).
// Truth (plate pose, point displacements, internal signals) and the interferometer's readings
// are exposed alongside, and the Fizeau cavity's optical path (fizeau_cavity.hpp). Every random
// number comes from one Rng seeded at construction, drawn in a fixed order, so the same seed and
// inputs give the same outputs bit for bit; the cavity's barometric drift alone draws from a
// second Rng seeded from the same seed (cavity_seed), so it changes no other draw.
//
// Faults: a per-channel ChannelFault (set_fault) covers what the later fault-injection work
// needs: amplifier off, SGS open or stuck, ADC NaN or spike, a cracked stack (stiffness loss).
//
// Real-time safe: write_ao, advance, read_ai, truth, interferometer (no heap, no
// exceptions, no I/O). Construction and set_fault are not.
#include <array>
#include <cstdint>
#include <vector>

#include "piezoshift/control/vec3.hpp"
#include "piezoshift/design/design_inputs.hpp"
#include "piezoshift/plant/creep.hpp"
#include "piezoshift/plant/fizeau_cavity.hpp"
#include "piezoshift/plant/flicker.hpp"
#include "piezoshift/plant/hysteresis.hpp"
#include "piezoshift/plant/lab_environment.hpp"
#include "piezoshift/plant/mechanics.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/plant/twin_model.hpp"
#include "piezoshift/plant/twin_params.hpp"

namespace piezoshift::plant {

using control::Vec3;

enum class AoStatus : std::uint8_t {
  kOk,
  kClamped,  //!< a value beyond the DAC's range: the converter's end code went out
  kInvalid,  //!< a non-finite value: that channel kept its previous output
};

struct TwinTruth {
  double time_s = 0.0;
  Vec3 ao_V{};                 //!< DAQ outputs as converted (quantized, held)
  Vec3 amplifier_V{};          //!< stack voltages
  Vec3 free_elongation_um{};   //!< x_free: hysteresis + creep, no load
  Vec3 stack_elongation_um{};  //!< e: what the strain gauges measure
  Vec3 leg_um{};               //!< x: mechanism outputs, where the plate sits
  double plate_z_um = 0.0;     //!< Z at O (centre of the actuator circle), since the start
  double theta_x_urad = 0.0;   //!< tip about x, since the start
  double theta_y_urad = 0.0;   //!< tilt about y, since the start
  Vec3 points_um{};            //!< displacement of P1..P3 since the start
  //! The extremes of mean(P1..P3) over the physics steps of the last period: overshoot and
  //! ringing between control ticks, which the tick-rate samples miss.
  double period_max_mean_points_um = 0.0;
  double period_min_mean_points_um = 0.0;
  //! mean(P1..P3) averaged over the physics steps of the last period: what a camera exposure of
  //! one period integrates (experiments/phase_step.hpp).
  double period_avg_mean_points_um = 0.0;
  Vec3 sgs_V{};  //!< conditioner outputs before the ADC (noise included)
  double air_temperature_C = 0.0;
  double structure_temperature_C = 0.0;
  // The sensor path's slow errors at the last AI sample (sgs.hpp, lab_environment.hpp):
  double sgs_excitation_drift_ppm = 0.0;  //!< delta, common to the three channels
  Vec3 sgs_zero_flicker_nm{};             //!< z_i
  Vec3 gauge_creep_um{};                  //!< d_i, in um of stack elongation
  double interferometer_drift_nm = 0.0;   //!< d(t), the lab's drift of every reading
  Vec3 contact_force_N{};                 //!< F0 + f, the ball contact's force (contact.hpp)
  Vec3 contact_residual_um{};             //!< r(f): Hertz beyond its linearization
  // The Fizeau cavity (fizeau_cavity.hpp), since the start; a positive value is a longer cavity:
  double air_pressure_Pa = 0.0;  //!< p, the barometric pressure
  double cavity_drift_nm = 0.0;  //!< d_c: the air's index over the gap and the mount
  double cavity_path_nm = 0.0;   //!< 1000 plate_z_um + d_c: what a fringe lock holds
};

struct InterferometerReading {
  Vec3 dynamic_um{};               //!< latest dynamic-mode sample of P1..P3
  double dynamic_time_s = 0.0;     //!< its time
  Vec3 static_um{};                //!< latest completed static-mode average of P1..P3
  double static_time_s = 0.0;      //!< end of its averaging window
  std::uint64_t static_count = 0;  //!< static readings completed so far
};

struct ChannelFault {
  bool amplifier_failed = false;       //!< amplifier input forced to 0 (output discharges)
  bool sgs_open = false;               //!< conditioner output at its positive rail
  bool sgs_stuck = false;              //!< conditioner output frozen at its last value
  bool adc_nan = false;                //!< the AI sample comes back as NaN
  double adc_spike_V = 0.0;            //!< added to the next AI sample only
  double stack_stiffness_scale = 1.0;  //!< k_a times this (a cracked stack: < 1)

  bool operator==(const ChannelFault&) const = default;
};

class Twin {
 public:
  //! Builds the twin at rest at 0 V (on the lower turning point of each stack's major loop, creep
  //! relaxed, interferometer datum at the start). Throws std::invalid_argument for parameters
  //! that cannot make a twin (see twin_params_problem).
  Twin(const design::DesignInputs& design, const TwinParams& params, std::uint64_t seed);

  //! Sets the DAQ outputs, held from now until the next write.
  AoStatus write_ao(const Vec3& ao_V) noexcept;
  //! One control period of physics, ending with one AI sample.
  void advance() noexcept;
  //! The AI volts of the last sample (zeros before the first advance()).
  const Vec3& read_ai() const noexcept { return ai_V_; }

  const TwinTruth& truth() const noexcept { return truth_; }
  const InterferometerReading& interferometer() const noexcept { return ifm_; }
  const TwinModel& model() const noexcept { return model_; }
  //! The piston the Fizeau's fringes see [nm]: the plate's Z, plus the cavity's drift when
  //! twin.cavity.in_fringes (the renderers' pose sources read this, not plate_z_um).
  double fringe_piston_nm() const noexcept {
    return model_.params.cavity.in_fringes ? truth_.cavity_path_nm : 1000.0 * truth_.plate_z_um;
  }
  double time_s() const noexcept { return truth_.time_s; }
  std::uint64_t ticks() const noexcept { return tick_; }
  std::uint64_t seed() const noexcept { return seed_; }

  //! Injects or clears a fault on channel i (0..2). Not real-time safe (a stiffness change
  //! re-discretizes the mechanics). Throws std::invalid_argument for a bad channel or scale.
  void set_fault(std::size_t channel, const ChannelFault& fault);
  const ChannelFault& fault(std::size_t channel) const { return faults_.at(channel); }

 private:
  void sample_interferometer(const Vec3& x_um, double t_s, double drift_um) noexcept;
  void sample_ai(double structure_change_K) noexcept;
  void update_truth(const Vec3& x_um) noexcept;
  //! mean(P1..P3) = this . (eta_1, eta_2, eta_3), the modal displacements.
  void update_mean_point_weights();
  double quantize_V(double v) const noexcept;

  TwinModel model_;
  std::uint64_t seed_;
  Rng rng_;
  LabEnvironment lab_;
  LabState lab_state_{};
  // The cavity draws from its own stream, so the draws above stay as they were without it.
  Rng cavity_rng_;
  FizeauCavity cavity_;
  CavityState cavity_state_{};
  double ifm_scale_ = 1.0;  // 1 + eps

  // Per-channel constants (copied from the model for locality; changed by faults)
  std::array<double, 3> ks_{};  // k_s [N/um]
  std::array<double, 3> ks_over_ka_{};
  std::array<double, 3> sgs_gain_{};      // g'_i
  double sgs_beta_ = 1.0;                 // conditioner filter, per physics step
  double ai_noise_V_ = 0.0;               // combined SGS and ADC noise per sample
  double lsb_V_ = 0.0, inv_lsb_V_ = 0.0;  // DAQ
  double code_min_ = 0.0, code_max_ = 0.0;
  LinearMechanics mechanics_;
  std::array<double, 3> mean_point_modal_{};    // see update_mean_point_weights
  std::vector<std::array<double, 3>> force_N_;  // stack forces of one period, per physics step

  // State
  std::uint64_t tick_ = 0;
  Vec3 ao_V_{};
  Vec3 amp_V_{};
  std::array<PlayState, 3> play_{};
  std::array<CreepState, 3> creep_{};
  Vec3 creep_out_{};
  std::array<CreepState, 3> gauge_creep_{};
  Vec3 gauge_out_{};
  FlickerState excitation_{};                   // delta's terms
  std::array<FlickerState, 3> zero_flicker_{};  // z_i's terms [nm]
  MechanicsState mech_{};
  Vec3 free_um_{};
  Vec3 elongation_um_{};
  // The conditioner's filter is linear, so it is run on the parts of e = (1 - k_s/k_a) x_free +
  // (k_s/k_a) x separately: on x_free and on the modal coordinates (x = Phi eta), which spares
  // forming x at every physics step.
  Vec3 filtered_free_um_{};
  Vec3 hertz_r_um_{};           // r, held over the period (contact.hpp)
  Vec3 filtered_hertz_r_um_{};  // r through the conditioner's filter
  double sgs_beta_tick_ = 0.0;  // the conditioner filter over one control period
  MechanicsState filtered_modes_{};
  Vec3 sgs_last_V_{};
  Vec3 ai_V_{};
  std::size_t ifm_countdown_ = 0;
  Vec3 static_sum_{};
  std::size_t static_n_ = 0;
  std::array<ChannelFault, 3> faults_{};
  TwinTruth truth_{};
  InterferometerReading ifm_{};
};

}  // namespace piezoshift::plant
