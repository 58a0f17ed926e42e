#include "piezoshift/io/project_config.hpp"

#include <fmt/core.h>

#include "piezoshift/io/input_error.hpp"

namespace piezoshift::io {

void read_design_sections(const ConfigFile& file, design::DesignInputs& design) {
  const Bounds positive = Bounds::positive();

  const ConfigSection actuator = file.section("actuator");
  design::ActuatorParams& a = design.actuator;
  actuator.read("stiffness_N_per_um", a.stiffness_N_per_um, positive);
  actuator.read("nominal_stroke_um", a.nominal_stroke_um, positive);
  actuator.read("pushing_force_N", a.pushing_force_N, positive);
  actuator.read("pulling_force_N", a.pulling_force_N, positive);
  actuator.read("capacitance_F", a.capacitance_F, positive);
  actuator.read("resonance_frequency_Hz", a.resonance_frequency_Hz, positive);
  actuator.read("length_m", a.length_m, positive);

  const ConfigSection material = file.section("material");
  design::MaterialParams& m = design.material;
  material.read("elastic_modulus_Pa", m.elastic_modulus_Pa, positive);
  material.read("poisson_ratio", m.poisson_ratio, Bounds::open(0.0, 0.5));
  material.read("density_kg_per_m3", m.density_kg_per_m3, positive);
  material.read("allowable_stress_Pa", m.allowable_stress_Pa, positive);

  const ConfigSection hinge = file.section("hinge");
  design::HingeParams& h = design.hinge;
  hinge.read("width_m", h.width_m, positive);
  hinge.read("thickness_m", h.thickness_m, positive);
  hinge.read("radius_m", h.radius_m, positive);
  hinge.read("link_length_m", h.link_length_m, positive);
  // The geometry involves two keys (one perhaps left at its default); the message names both.
  if (const std::string problem = design::hinge_geometry_problem(h); !problem.empty())
    throw InputError(fmt::format("{}: {}", file.source(), problem));

  const ConfigSection mechanism = file.section("mechanism");
  mechanism.read("moving_mass_kg", design.mechanism.moving_mass_kg, positive);
}

void read_twin_sections(const ConfigFile& file, const design::DesignInputs& design,
                        plant::TwinParams& t) {
  const Bounds positive = Bounds::positive();
  const Bounds non_negative = Bounds::non_negative();
  const Bounds ratio = Bounds{0.0, 1.0, false, true};  // [0, 1)

  file.section("twin").read("physics_rate_Hz", t.physics_rate_Hz, positive);

  const ConfigSection daq = file.section("twin.daq");
  daq.read("sample_time_s", t.daq.sample_time_s, positive);
  daq.read("range_V", t.daq.range_V, positive);
  daq.read("resolution_bits", t.daq.resolution_bits, Bounds::closed(2, 32));
  daq.read("ai_noise_V_rms", t.daq.ai_noise_V_rms, non_negative);

  const ConfigSection amp = file.section("twin.amplifier");
  amp.read("gain", t.amplifier.gain, positive);
  amp.read("output_min_V", t.amplifier.output_min_V);
  amp.read("output_max_V", t.amplifier.output_max_V, positive);
  amp.read("average_power_W", t.amplifier.average_power_W, positive);
  amp.read("small_signal_bandwidth_Hz", t.amplifier.small_signal_bandwidth_Hz, positive);

  const ConfigSection piezo = file.section("twin.piezo");
  piezo.read("hysteresis_fraction", t.piezo.hysteresis.hysteresis_fraction,
             Bounds{0.0, 0.5, false, true});
  piezo.read("play_operators", t.piezo.hysteresis.play_operators, Bounds::closed(1, 32));
  piezo.read("creep_per_decade", t.piezo.creep.per_decade_fraction, Bounds::closed(0.0, 0.2));
  piezo.read("creep_shortest_time_constant_s", t.piezo.creep.shortest_time_constant_s, positive);
  piezo.read("creep_longest_time_constant_s", t.piezo.creep.longest_time_constant_s, positive);
  piezo.read("creep_terms_per_decade", t.piezo.creep.terms_per_decade, Bounds::closed(1, 10));
  piezo.read("creep_reference_time_s", t.piezo.creep_reference_time_s, positive);
  piezo.read("free_stroke_scale", t.piezo.free_stroke_scale, positive);

  const ConfigSection contact = file.section("twin.contact");
  contact.read("open_loop_travel_um", t.contact.open_loop_travel_um, positive);
  contact.read("open_loop_time_s", t.contact.open_loop_time_s, positive);
  if (double k = 0.0; contact.read("stiffness_N_per_um", k, positive))
    t.contact.stiffness_N_per_um = k;
  contact.read("ball_radius_m", t.contact.ball_radius_m, non_negative);
  if (double f = 0.0; contact.read("preload_N", f, positive))
    t.contact.preload_N = f;

  const ConfigSection mech = file.section("twin.mechanics");
  mech.read("mechanism_damping_ratio", t.mechanics.mechanism_damping_ratio, ratio);
  mech.read("modal_damping_ratio", t.mechanics.modal_damping_ratio, ratio);

  const ConfigSection plate = file.section("twin.plate");
  plate.read("radius_m", t.plate.radius_m, positive);
  plate.read("thickness_m", t.plate.thickness_m, positive);
  plate.read("payload_mass_kg", t.plate.payload_mass_kg, non_negative);

  const ConfigSection geo = file.section("twin.geometry");
  geo.read("actuator_radius_m", t.geometry.actuator_radius_m, positive);
  geo.read("first_actuator_angle_deg", t.geometry.first_actuator_angle_deg,
           Bounds::closed(-360.0, 360.0));
  geo.read("transmission_matrix", t.geometry.transmission_matrix);
  geo.read("height_errors_um", t.geometry.height_errors_um);

  const ConfigSection sgs = file.section("twin.sgs");
  sgs.read("full_scale_V", t.sgs.full_scale_V, positive);
  sgs.read("nonlinearity_fraction", t.sgs.nonlinearity_fraction, Bounds::closed(0.0, 0.1));
  if (std::string shape; sgs.read("nonlinearity_shape", shape)) {
    if (shape == "bow")
      t.sgs.nonlinearity_shape = plant::SgsNonlinearityShape::kBow;
    else if (shape == "s_curve")
      t.sgs.nonlinearity_shape = plant::SgsNonlinearityShape::kSCurve;
    else if (shape == "wave")
      t.sgs.nonlinearity_shape = plant::SgsNonlinearityShape::kWave;
    else
      throw InputError(
          fmt::format("{}: twin.sgs.nonlinearity_shape: '{}' is not one of bow, s_curve, wave",
                      file.source(), shape));
  }
  sgs.read("noise_nm_rms", t.sgs.noise_nm_rms, non_negative);
  sgs.read("bandwidth_Hz", t.sgs.bandwidth_Hz, positive);
  sgs.read("offset_V", t.sgs.offset_V);
  sgs.read("zero_drift_nm_per_K", t.sgs.zero_drift_nm_per_K);
  sgs.read("gauge_creep_fraction", t.sgs.gauge_creep_fraction, Bounds::closed(0.0, 0.1));
  sgs.read("gauge_creep_time_s", t.sgs.gauge_creep_time_s, positive);
  sgs.read("flicker_corner_Hz", t.sgs.flicker_corner_Hz, non_negative);
  sgs.read("excitation_drift_ppm_rms", t.sgs.excitation_drift_ppm_rms, non_negative);
  sgs.read("excitation_drift_window_s", t.sgs.excitation_drift_window_s, positive);

  const ConfigSection ifm = file.section("twin.interferometer");
  ifm.read("wavelength_nm", t.interferometer.wavelength_nm, positive);
  ifm.read("resolution_nm", t.interferometer.resolution_nm, positive);
  ifm.read("accuracy_ppm", t.interferometer.accuracy_ppm, non_negative);
  ifm.read("noise_nm_rms", t.interferometer.noise_nm_rms, non_negative);
  ifm.read("cyclic_error_nm", t.interferometer.cyclic_error_nm, non_negative);
  ifm.read("dynamic_sample_rate_Hz", t.interferometer.dynamic_sample_rate_Hz, positive);
  ifm.read("static_average_s", t.interferometer.static_average_s, positive);

  const ConfigSection lab = file.section("twin.lab");
  lab.read("temperature_C", t.lab.temperature_C);
  lab.read("temperature_rms_K", t.lab.temperature_rms_K, non_negative);
  lab.read("temperature_correlation_time_s", t.lab.temperature_correlation_time_s, positive);
  lab.read("structure_time_constant_s", t.lab.structure_time_constant_s, positive);
  lab.read("metrology_loop_length_m", t.lab.metrology_loop_length_m, non_negative);
  lab.read("metrology_loop_cte_per_K", t.lab.metrology_loop_cte_per_K);
  lab.read("dead_path_m", t.lab.dead_path_m, non_negative);
  lab.read("air_index_per_K", t.lab.air_index_per_K);

  // What one key's bounds cannot say (rates that must divide, the contact identification, A).
  if (const std::string problem = plant::twin_params_problem(design, t); !problem.empty())
    throw InputError(fmt::format("{}: {}", file.source(), problem));
}

ProjectConfig load_project_config(const std::string& path) {
  const ConfigFile file = ConfigFile::load(path);
  ProjectConfig config;
  read_design_sections(file, config.design);
  read_twin_sections(file, config.design, config.twin);
  file.reject_unknown();
  return config;
}

}  // namespace piezoshift::io
