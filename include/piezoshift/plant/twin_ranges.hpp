#pragma once
// The valid range of every twin parameter, in one place: the TOML reader (io/project_config.cpp),
// make_twin_model() (and so twin_params_problem(), the Python bindings and every Twin) walk this
// list. The ranges are chosen so that every accepted combination builds a twin whose memory is
// bounded and whose cost per control tick is bounded (at most kMaxPhysicsStepsPerTick physics
// steps): how long a run takes is then the caller's duration times that cost, which the callers
// estimate before they start (plant/simulation_cost.hpp). docs/twin.md lists them.
//
//   visit_twin_values(params, [](const char* section, const char* key, auto& value,
//                                core::Bounds bounds) { ... });
#include <cstdint>
#include <string>

#include "piezoshift/core/bounds.hpp"
#include "piezoshift/plant/sgs.hpp"
#include "piezoshift/plant/twin_params.hpp"

namespace piezoshift::plant {

//! physics_rate_Hz * daq.sample_time_s, the physics steps in one control tick, at most this: the
//! default is 20; 10 000 steps of about 60 ns are 0.6 ms of work per tick.
inline constexpr double kMaxPhysicsStepsPerTick = 10000.0;

namespace detail {

// The twin's drive chain, in paper.toml's order: the timing, [twin.daq], [twin.amplifier] and
// [twin.piezo] (visit_twin_values visits these first).
template <typename Twin, typename Visit>
void visit_twin_drive_values(Twin& t, Visit& visit) {
  using B = core::Bounds;
  // Timing: the 20 kHz default; up to 10 MHz (with the per-tick limit above) and down to 1 Hz.
  visit("twin", "physics_rate_Hz", t.physics_rate_Hz, B::closed(1.0, 1e7));
  // 10 us (100 kHz) to 1 s: the PCI-6229's fastest loop to the slowest useful one.
  visit("twin.daq", "sample_time_s", t.daq.sample_time_s, B::closed(1e-5, 1.0));
  // +-0.1 to +-10 V: the ranges of NI's M Series (the PCI-6229's +-10 V the largest); a denormal
  // range made every code 0 V and the stage never moved.
  visit("twin.daq", "range_V", t.daq.range_V, B::closed(0.1, 10.0));
  // 12 bits (the coarsest multifunction DAQs, NI's USB-6008) to 32: 2 bits gave 5 V steps (an
  // AO step of 8 um at the plate) and the procedures failed without naming the key.
  visit("twin.daq", "resolution_bits", t.daq.resolution_bits, B::closed(12, 32));
  visit("twin.daq", "ai_noise_V_rms", t.daq.ai_noise_V_rms, B::closed(0.0, 10.0));

  // 1 (a follower) to 1000 V/V (high-voltage amplifiers' largest): 5e-324 left the stacks at 0 V.
  visit("twin.amplifier", "gain", t.amplifier.gain, B::closed(1.0, 1000.0));
  visit("twin.amplifier", "output_min_V", t.amplifier.output_min_V, B::closed(-1000.0, 1000.0));
  // At least 1 V: the hysteresis model works on the input over this span (a denormal span made
  // it infinite).
  visit("twin.amplifier", "output_max_V", t.amplifier.output_max_V, B::closed(1.0, 1000.0));
  // At least 0.1 W: a 0-150 V step into Table 1's 1.8 uF in 0.4 s (S = P / V_max / C); a
  // denormal power never charged the stacks.
  visit("twin.amplifier", "average_power_W", t.amplifier.average_power_W, B::closed(0.1, 1e4));
  // At least 1 Hz, the slowest loop's rate (daq.sample_time_s <= 1 s): below, no command is
  // followed within a run.
  visit("twin.amplifier", "small_signal_bandwidth_Hz", t.amplifier.small_signal_bandwidth_Hz,
        B::closed(1.0, 1e7));

  visit("twin.piezo", "hysteresis_fraction", t.piezo.hysteresis.hysteresis_fraction,
        B{0.0, 0.5, false, true});
  visit("twin.piezo", "play_operators", t.piezo.hysteresis.play_operators, B::closed(1, 32));
  visit("twin.piezo", "creep_per_decade", t.piezo.creep.per_decade_fraction, B::closed(0.0, 0.2));
  // 1 us to ~30 years: at most 15 decades of creep terms.
  visit("twin.piezo", "creep_shortest_time_constant_s", t.piezo.creep.shortest_time_constant_s,
        B::closed(1e-6, 1e9));
  visit("twin.piezo", "creep_longest_time_constant_s", t.piezo.creep.longest_time_constant_s,
        B::closed(1e-6, 1e9));
  visit("twin.piezo", "creep_terms_per_decade", t.piezo.creep.terms_per_decade, B::closed(1, 10));
  visit("twin.piezo", "creep_reference_time_s", t.piezo.creep_reference_time_s, B::above(0.0, 1e9));
  // 0.5 to 1.5 of nominal: stacks' stroke tolerance is +-10 to 15 % (PI) and the tolerance
  // studies draw +-9 %; a denormal scale failed as a contact that could not be identified.
  visit("twin.piezo", "free_stroke_scale", t.piezo.free_stroke_scale, B::closed(0.5, 1.5));
}

}  // namespace detail

//! Calls visit(section, key, value, bounds) for each value of twin (const or not) that has a
//! numeric range, in the order of configs/paper.toml; section and key are the TOML names
//! ("twin.daq", "sample_time_s"). value is a double, std::int64_t, std::array<double, 3>,
//! std::optional<double> or a 3x3 matrix; each element is checked against bounds.
template <typename Twin, typename Visit>
void visit_twin_values(Twin& t, Visit&& visit) {
  using B = core::Bounds;
  detail::visit_twin_drive_values(t, visit);

  visit("twin.contact", "open_loop_travel_um", t.contact.open_loop_travel_um, B::above(0.0, 1e4));
  visit("twin.contact", "open_loop_time_s", t.contact.open_loop_time_s, B::above(0.0, 1e9));
  visit("twin.contact", "stiffness_N_per_um", t.contact.stiffness_N_per_um, B::above(0.0, 1e6));
  visit("twin.contact", "ball_radius_m", t.contact.ball_radius_m, B::closed(0.0, 1.0));
  visit("twin.contact", "preload_N", t.contact.preload_N, B::above(0.0, 1e7));

  visit("twin.mechanics", "mechanism_damping_ratio", t.mechanics.mechanism_damping_ratio,
        B{0.0, 1.0, false, true});
  visit("twin.mechanics", "modal_damping_ratio", t.mechanics.modal_damping_ratio,
        B{0.0, 1.0, false, true});

  visit("twin.plate", "radius_m", t.plate.radius_m, B::above(0.0, 10.0));
  visit("twin.plate", "thickness_m", t.plate.thickness_m, B::above(0.0, 1.0));
  visit("twin.plate", "payload_mass_kg", t.plate.payload_mass_kg, B::closed(0.0, 1e4));

  visit("twin.geometry", "actuator_radius_m", t.geometry.actuator_radius_m, B::above(0.0, 10.0));
  visit("twin.geometry", "first_actuator_angle_deg", t.geometry.first_actuator_angle_deg,
        B::closed(-360.0, 360.0));
  visit("twin.geometry", "transmission_matrix", t.geometry.transmission_matrix,
        B::closed(-100.0, 100.0));
  visit("twin.geometry", "height_errors_um", t.geometry.height_errors_um,
        B::closed(-1000.0, 1000.0));

  visit("twin.sgs", "full_scale_V", t.sgs.full_scale_V, B::above(0.0, 1000.0));
  visit("twin.sgs", "nonlinearity_fraction", t.sgs.nonlinearity_fraction, B::closed(0.0, 0.1));
  visit("twin.sgs", "noise_nm_rms", t.sgs.noise_nm_rms, B::closed(0.0, 1e4));
  visit("twin.sgs", "bandwidth_Hz", t.sgs.bandwidth_Hz, B::above(0.0, 1e7));
  visit("twin.sgs", "offset_V", t.sgs.offset_V, B::closed(-100.0, 100.0));
  visit("twin.sgs", "zero_drift_nm_per_K", t.sgs.zero_drift_nm_per_K, B::closed(-1e6, 1e6));
  visit("twin.sgs", "gauge_creep_fraction", t.sgs.gauge_creep_fraction, B::closed(0.0, 0.1));
  // At least 1 ms (one control period at 1 kHz): the creep a step shows sooner is ~0, and
  // dividing by it failed as a negative per-decade fraction.
  visit("twin.sgs", "gauge_creep_time_s", t.sgs.gauge_creep_time_s, B::closed(1e-3, 1e9));
  visit("twin.sgs", "flicker_corner_Hz", t.sgs.flicker_corner_Hz, B::closed(0.0, 1e6));
  visit("twin.sgs", "excitation_drift_ppm_rms", t.sgs.excitation_drift_ppm_rms,
        B::closed(0.0, 1e6));
  // At least the excitation flicker's shortest time (sgs.hpp): over a shorter window it has no
  // variance to state, and the level came out infinite.
  visit("twin.sgs", "excitation_drift_window_s", t.sgs.excitation_drift_window_s,
        B::closed(kSgsExcitationShortestS, 1e9));

  visit("twin.interferometer", "wavelength_nm", t.interferometer.wavelength_nm, B::above(0.0, 1e5));
  // At least 1 pm, the finest of displacement interferometers (the XL-80's: 1 nm); a denormal
  // resolution made every reading infinite.
  visit("twin.interferometer", "resolution_nm", t.interferometer.resolution_nm,
        B::closed(1e-3, 1e6));
  visit("twin.interferometer", "accuracy_ppm", t.interferometer.accuracy_ppm, B::closed(0.0, 1e6));
  visit("twin.interferometer", "noise_nm_rms", t.interferometer.noise_nm_rms, B::closed(0.0, 1e6));
  visit("twin.interferometer", "cyclic_error_nm", t.interferometer.cyclic_error_nm,
        B::closed(0.0, 1e6));
  visit("twin.interferometer", "dynamic_sample_rate_Hz", t.interferometer.dynamic_sample_rate_Hz,
        B::above(0.0, 1e7));
  visit("twin.interferometer", "static_average_s", t.interferometer.static_average_s,
        B::above(0.0, 1e6));

  visit("twin.lab", "temperature_C", t.lab.temperature_C, B::closed(-100.0, 200.0));
  visit("twin.lab", "temperature_rms_K", t.lab.temperature_rms_K, B::closed(0.0, 100.0));
  visit("twin.lab", "temperature_correlation_time_s", t.lab.temperature_correlation_time_s,
        B::above(0.0, 1e9));
  visit("twin.lab", "structure_time_constant_s", t.lab.structure_time_constant_s,
        B::above(0.0, 1e9));
  visit("twin.lab", "metrology_loop_length_m", t.lab.metrology_loop_length_m,
        B::closed(0.0, 100.0));
  visit("twin.lab", "metrology_loop_cte_per_K", t.lab.metrology_loop_cte_per_K,
        B::closed(-1e-3, 1e-3));
  visit("twin.lab", "dead_path_m", t.lab.dead_path_m, B::closed(0.0, 1000.0));
  visit("twin.lab", "air_index_per_K", t.lab.air_index_per_K, B::closed(-1e-3, 1e-3));

  visit("twin.cavity", "gap_m", t.cavity.gap_m, B::closed(0.0, 10.0));
  // Edlen's dispersion term has poles below 160 nm; NIST's calculators take 300 to 1700 nm.
  visit("twin.cavity", "wavelength_nm", t.cavity.wavelength_nm, B::closed(300.0, 1700.0));
  // From a high-altitude lab to a pressurized room: Birch and Downs fitted near 100 kPa.
  visit("twin.cavity", "pressure_Pa", t.cavity.pressure_Pa, B::closed(5e4, 1.2e5));
  visit("twin.cavity", "pressure_rate_rms_Pa_per_s", t.cavity.pressure_rate_rms_Pa_per_s,
        B::closed(0.0, 100.0));
  visit("twin.cavity", "pressure_rate_correlation_time_s",
        t.cavity.pressure_rate_correlation_time_s, B::above(0.0, 1e9));
  // Up to the saturation pressure at 40 degC (7.4 kPa).
  visit("twin.cavity", "water_vapour_pressure_Pa", t.cavity.water_vapour_pressure_Pa,
        B::closed(0.0, 7400.0));
  visit("twin.cavity", "mount_path_length_m", t.cavity.mount_path_length_m, B::closed(-10.0, 10.0));
  visit("twin.cavity", "mount_cte_per_K", t.cavity.mount_cte_per_K, B::closed(-1e-3, 1e-3));
}

//! The first value of twin outside its range ("twin.daq.sample_time_s = 1000000 must be in
//! [1e-05, 1]"), or "" when every value is within range.
std::string twin_ranges_problem(const TwinParams& twin);

}  // namespace piezoshift::plant
