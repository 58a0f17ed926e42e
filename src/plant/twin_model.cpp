#include "piezoshift/plant/twin_model.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <fmt/core.h>
#include <Eigen/LU>

#include "piezoshift/design/flexure.hpp"
#include "piezoshift/design/natural_frequency.hpp"
#include "piezoshift/kinematics/tripod.hpp"
#include "piezoshift/plant/contact.hpp"
#include "piezoshift/plant/twin_ranges.hpp"

namespace piezoshift::plant {
namespace {

[[noreturn]] void fail(const std::string& message) {
  throw std::invalid_argument(message);
}

void require(bool ok, const std::string& message) {
  if (!ok)
    fail(message);
}

// n = value when value is (to rounding) a whole number >= 1.
std::size_t whole_number(double value, const std::string& what) {
  const double n = std::round(value);
  require(std::isfinite(value) && n >= 1.0 && std::fabs(value - n) <= 1e-9 * std::fmax(1.0, n),
          fmt::format("{} is {}, which must be a whole number >= 1", what, value));
  return static_cast<std::size_t>(n);
}

// Component constructors throw with their own wording; prefix the TOML section.
template <typename Make>
auto built(const char* section, Make make) {
  try {
    return make();
  } catch (const std::invalid_argument& e) {
    fail(fmt::format("{}: {}", section, e.what()));
  }
}

// Timing: the per-tick physics cost is bounded (kMaxPhysicsStepsPerTick).
void set_timing(TwinModel& m, const TwinParams& p) {
  require(p.physics_rate_Hz * p.daq.sample_time_s <= kMaxPhysicsStepsPerTick * (1.0 + 1e-9),
          fmt::format("twin.physics_rate_Hz * twin.daq.sample_time_s = {} physics steps per "
                      "control tick is more than the twin's limit of {}",
                      p.physics_rate_Hz * p.daq.sample_time_s, kMaxPhysicsStepsPerTick));
  m.control_period_s = p.daq.sample_time_s;
  m.substeps = whole_number(p.physics_rate_Hz * p.daq.sample_time_s,
                            "twin.physics_rate_Hz * twin.daq.sample_time_s (physics steps per "
                            "control period)");
  m.physics_step_s = p.daq.sample_time_s / static_cast<double>(m.substeps);
  m.interferometer_every = whole_number(
      p.physics_rate_Hz / p.interferometer.dynamic_sample_rate_Hz,
      "twin.physics_rate_Hz / twin.interferometer.dynamic_sample_rate_Hz (physics steps per "
      "interferometer sample)");
  m.interferometer_static_samples = whole_number(
      p.interferometer.static_average_s * p.interferometer.dynamic_sample_rate_Hz,
      "twin.interferometer.static_average_s * twin.interferometer.dynamic_sample_rate_Hz "
      "(samples per static reading)");
}

// DAQ, amplifier
void set_amplifier(TwinModel& m, const design::DesignInputs& d, const TwinParams& p) {
  const AmplifierParams& amp = p.amplifier;
  require(amp.output_min_V < amp.output_max_V,
          "twin.amplifier.output_min_V must be below twin.amplifier.output_max_V");
  m.amplifier = Amplifier(amp, d.actuator.capacitance_F, m.physics_step_s);
  m.amplifier_current_limit_A = amplifier_current_limit_A(amp);
  m.amplifier_slew_V_per_s = amplifier_slew_rate_V_per_s(amp, d.actuator.capacitance_F);
}

// 1 + C_step(t_ref): the creep factor at which the strokes are stated.
double reference_creep_factor(const TwinModel& m, const TwinParams& p) {
  return 1.0 + m.creep.step_response(p.piezo.creep_reference_time_s);
}

// Stack: hysteresis over the amplifier's full output, creep at the control period
void set_stack(TwinModel& m, const design::DesignInputs& d, const TwinParams& p) {
  m.hysteresis = built("twin.piezo", [&] {
    return PrandtlIshlinskii(p.piezo.hysteresis, p.amplifier.output_max_V);
  });
  m.creep = built(
      "twin.piezo (creep_shortest_time_constant_s, creep_longest_time_constant_s, "
      "creep_terms_per_decade)",
      [&] { return CreepChain(p.piezo.creep, m.control_period_s); });
  const double f_ref = reference_creep_factor(m, p);
  for (std::size_t i = 0; i < 3; ++i) {
    const double s = p.piezo.free_stroke_scale[i];
    m.free_stroke_um[i] = d.actuator.nominal_stroke_um * s;
    m.stroke_gain_um[i] = m.free_stroke_um[i] / f_ref;
  }
}

// What the contact is identified from, named when it cannot be.
constexpr const char* kContactKeys =
    "twin.contact (open_loop_travel_um, open_loop_time_s, ball_radius_m, preload_N; with "
    "twin.piezo.free_stroke_scale)";

// The contact's stiffness from the open-loop travel: given, Hertz (its preload given or
// identified), or linear identified. free_at_measurement: the stacks' mean free stroke when the
// travel was measured [um].
void set_contact(TwinModel& m, const TwinParams& p, double free_at_measurement) {
  const double km = m.mechanism_stiffness_N_per_um, ka = m.actuator_stiffness_N_per_um;
  const double travel = p.contact.open_loop_travel_um;
  if (p.contact.stiffness_N_per_um.has_value()) {
    m.contact_stiffness_N_per_um = *p.contact.stiffness_N_per_um;
  } else if (p.contact.ball_radius_m > 0.0 &&
             (p.contact.preload_N.has_value() ||
              hertz_preload_reachable(travel, free_at_measurement, ka, km, p.contact.ball_radius_m,
                                      m.contact_modulus_Pa))) {
    const double r = p.contact.ball_radius_m, e = m.contact_modulus_Pa;
    m.contact_hertz = true;
    if (p.contact.preload_N.has_value()) {
      m.contact_preload_N = *p.contact.preload_N;
    } else {
      m.contact_preload_N = built(kContactKeys, [&] {
        return identify_hertz_preload_N(travel, free_at_measurement, ka, km, r, e);
      });
      m.contact_preload_identified = true;
    }
    m.contact_identified = m.contact_preload_identified;
    m.contact_stiffness_N_per_um = hertz_stiffness_N_per_um(m.contact_preload_N, r, e);
    m.hertz = make_hertz_residual(m.contact_preload_N, r, e);
    m.contact_secant_N_per_um = km * travel /
                                (hertz_deflection_um(m.contact_preload_N + km * travel, r, e) -
                                 hertz_deflection_um(m.contact_preload_N, r, e));
  } else {
    // ball_radius_m = 0, or a design whose mechanism is so soft that no preload's Hertz contact
    // gives up enough stroke (a design study with another hinge): the linear contact
    // identified from the same travel.
    m.contact_stiffness_N_per_um = built(kContactKeys, [&] {
      return identify_contact_stiffness_N_per_um(travel, free_at_measurement, ka, km);
    });
    m.contact_identified = true;
  }
  if (!m.contact_hertz)
    m.contact_secant_N_per_um = m.contact_stiffness_N_per_um;
}

// Stiffness: mechanism from the design's Eqs. 2-3, actuator from Table 1, contact identified
void set_stiffness(TwinModel& m, const design::DesignInputs& d, const TwinParams& p) {
  m.mechanism_stiffness_N_per_um = design::mechanism_stiffness_N_per_um(d.material, d.hinge);
  m.actuator_stiffness_N_per_um = d.actuator.stiffness_N_per_um;
  const double km = m.mechanism_stiffness_N_per_um, ka = m.actuator_stiffness_N_per_um;
  m.open_loop_creep_factor =
      (1.0 + m.creep.step_response(p.contact.open_loop_time_s)) / reference_creep_factor(m, p);
  double scale_sum = 0.0;
  for (std::size_t i = 0; i < 3; ++i)
    scale_sum += p.piezo.free_stroke_scale[i];
  const double free_at_measurement =
      d.actuator.nominal_stroke_um * scale_sum / 3.0 * m.open_loop_creep_factor;
  m.contact_modulus_Pa =
      hertz_contact_modulus_Pa(d.material.elastic_modulus_Pa, d.material.poisson_ratio);
  set_contact(m, p, free_at_measurement);
  m.series_stiffness_N_per_um = series_stiffness_N_per_um(ka, m.contact_stiffness_N_per_um);
  const double ks = m.series_stiffness_N_per_um;
  m.equation1_um = design::available_displacement_um(d.actuator, km);
  for (std::size_t i = 0; i < 3; ++i) {
    m.leg_static_um[i] = m.contact_hertz
                             ? hertz_static_leg_um(m.free_stroke_um[i], ka, km, m.contact_preload_N,
                                                   p.contact.ball_radius_m, m.contact_modulus_Pa)
                             : m.free_stroke_um[i] * ks / (ks + km);
  }
}

// Masses
void set_masses(TwinModel& m, const design::DesignInputs& d, const TwinParams& p) {
  m.mechanism_mass_kg = d.mechanism.moving_mass_kg;
  const double w_a = 2.0 * std::numbers::pi * d.actuator.resonance_frequency_Hz;
  m.stack_mass_kg = m.actuator_stiffness_N_per_um * 1e6 / (w_a * w_a);
  m.leg_mass_kg = m.mechanism_mass_kg + m.stack_mass_kg;
  m.plate = plate_inertia(p.plate, d.material.density_kg_per_m3);
}

// Geometry: the measurement points on the plate, the legs' effect on the plate's pose
void set_geometry(TwinModel& m, const TwinParams& p) {
  m.geometry =
      built("twin.geometry (actuator_radius_m, first_actuator_angle_deg, transmission_matrix)",
            [&] { return make_twin_geometry(p.geometry); });
  for (std::size_t j = 0; j < 3; ++j) {
    const double r = std::hypot(m.geometry.points[j].x_m, m.geometry.points[j].y_m);
    require(r <= p.plate.radius_m,
            fmt::format("twin.plate.radius_m = {} m does not reach measurement point P{}, {:.4f} m "
                        "from the centre (twin.geometry.actuator_radius_m = {} m)",
                        p.plate.radius_m, j + 1, r, p.geometry.actuator_radius_m));
  }
  const kinematics::TripodGeometry legs(m.geometry.actuators);
  for (std::size_t i = 0; i < 3; ++i) {
    std::array<double, 3> unit{0.0, 0.0, 0.0};
    unit[i] = 1.0;
    const kinematics::PlatePose pose = legs.forward(unit);
    m.legs_to_pose[0][i] = pose.z_um;
    m.legs_to_pose[1][i] = pose.theta_x_urad;
    m.legs_to_pose[2][i] = pose.theta_y_urad;
  }
}

// Sensors: the strain gauges' gain, creep and flicker
void set_gauges(TwinModel& m, const design::DesignInputs& d, const TwinParams& p) {
  const SgsParams& sgs = p.sgs;
  for (std::size_t i = 0; i < 3; ++i) {
    m.sgs_gain_per_elongation[i] =
        m.geometry.sgs_gain[i] / (1.0 + m.mechanism_stiffness_N_per_um / m.contact_secant_N_per_um);
  }
  m.sgs_nominal_um_per_V = d.actuator.nominal_stroke_um / sgs.full_scale_V;
  // Gauge creep: the stack's chain, scaled so a step creeps by the stated fraction in the
  // stated time (creep.hpp: the step response is linear in the per-decade fraction).
  CreepParams gauge = p.piezo.creep;
  gauge.per_decade_fraction = 1.0;
  const double unit_creep = built("twin.sgs", [&] {
                              return CreepChain(gauge, m.control_period_s);
                            }).step_response(sgs.gauge_creep_time_s);
  gauge.per_decade_fraction = sgs.gauge_creep_fraction / unit_creep;
  m.gauge_creep = built("twin.sgs", [&] { return CreepChain(gauge, m.control_period_s); });
  // Flicker: the zero's 1/f level A = S_white f_corner, S_white = sigma^2 / (f_s / 2); the
  // excitation's level from its rms over the stated window (flicker.hpp).
  const double white_psd_nm2_per_Hz =
      sgs.noise_nm_rms * sgs.noise_nm_rms / (0.5 / m.control_period_s);
  m.sgs_zero_flicker =
      FlickerNoise(white_psd_nm2_per_Hz * sgs.flicker_corner_Hz, kSgsZeroFlickerShortestS,
                   kSgsFlickerLongestS, 1, m.control_period_s);
  m.sgs_excitation_drift = FlickerNoise(
      flicker_psd_for_window_rms(sgs.excitation_drift_ppm_rms * 1e-6, sgs.excitation_drift_window_s,
                                 kSgsExcitationShortestS, kSgsFlickerLongestS, 1),
      kSgsExcitationShortestS, kSgsFlickerLongestS, 1, m.control_period_s);
}

}  // namespace

LinearMechanics make_leg_plate_mechanics(const TwinModel& m,
                                         const std::array<double, 3>& leg_stiffness_N_per_um) {
  // x = T q with T rows [1, y_i, -x_i] (metres, radians): the plate's kinetic energy in leg
  // coordinates is 1/2 x'^T T^-T M_p T^-1 x'.
  Eigen::Matrix3d t;
  for (Eigen::Index i = 0; i < 3; ++i) {
    const auto& a = m.geometry.actuators[static_cast<std::size_t>(i)];
    t.row(i) << 1.0, a.y_m, -a.x_m;
  }
  const Eigen::Matrix3d t_inv = t.inverse();
  const Eigen::Vector3d mp(m.plate.mass_kg, m.plate.inertia_x_kg_m2, m.plate.inertia_y_kg_m2);
  Eigen::Matrix3d mass = t_inv.transpose() * mp.asDiagonal() * t_inv;
  mass.diagonal().array() += m.leg_mass_kg;
  mass = 0.5 * (mass + mass.transpose());
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
  for (Eigen::Index i = 0; i < 3; ++i)
    k(i, i) = 1e6 * leg_stiffness_N_per_um[static_cast<std::size_t>(i)];
  return LinearMechanics(mass, k, m.params.mechanics.modal_damping_ratio, m.physics_step_s);
}

TwinModel make_twin_model(const design::DesignInputs& d, const TwinParams& p) {
  if (const std::string problem = design::design_inputs_problem(d); !problem.empty())
    fail(problem);
  // Every value within its range first (twin_ranges.hpp); what follows checks combinations.
  if (const std::string problem = twin_ranges_problem(p); !problem.empty())
    fail(problem);
  TwinModel m;
  m.design = d;
  m.params = p;
  set_timing(m, p);
  set_amplifier(m, d, p);
  set_stack(m, d, p);
  set_stiffness(m, d, p);
  set_masses(m, d, p);
  set_geometry(m, p);
  set_gauges(m, d, p);

  // Dynamics
  const double km = m.mechanism_stiffness_N_per_um, ks = m.series_stiffness_N_per_um;
  m.mechanics = make_leg_plate_mechanics(m, {km + ks, km + ks, km + ks});
  m.loaded_modes_Hz = m.mechanics.natural_frequencies_Hz();
  m.unloaded_mechanism_Hz = design::natural_frequency_Hz(km, m.mechanism_mass_kg);
  m.leg_with_stack_Hz = design::natural_frequency_Hz(km + ks, m.leg_mass_kg);
  return m;
}

std::string twin_params_problem(const design::DesignInputs& design, const TwinParams& twin) {
  try {
    (void)make_twin_model(design, twin);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return {};
}

}  // namespace piezoshift::plant
