#include "piezoshift/plant/twin.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/LU>

#include "piezoshift/plant/daq.hpp"
#include "piezoshift/plant/interferometer.hpp"
#include "piezoshift/plant/sgs.hpp"

namespace piezoshift::plant {

Twin::Twin(const design::DesignInputs& design, const TwinParams& params, std::uint64_t seed)
    : model_(make_twin_model(design, params)),
      seed_(seed),
      rng_(seed),
      cavity_rng_(cavity_seed(seed)) {
  const TwinParams& p = model_.params;
  // The run's draws at construction, in this order: the lab's start (2 deviates), the
  // interferometer's scale error, the excitation drift's terms, each channel's zero flicker terms
  // (all stationary starts).
  lab_ = LabEnvironment(p.lab, model_.control_period_s);
  lab_.start(lab_state_, rng_);
  cavity_ = FizeauCavity(p.cavity, model_.control_period_s);
  cavity_.start(cavity_state_, lab_, lab_state_, cavity_rng_);
  ifm_scale_ = 1.0 + p.interferometer.accuracy_ppm * 1e-6 * (2.0 * rng_.uniform() - 1.0);
  model_.sgs_excitation_drift.start(excitation_, rng_);
  for (std::size_t i = 0; i < 3; ++i)
    model_.sgs_zero_flicker.start(zero_flicker_[i], rng_);

  for (std::size_t i = 0; i < 3; ++i) {
    ks_[i] = model_.series_stiffness_N_per_um;
    ks_over_ka_[i] = ks_[i] / model_.actuator_stiffness_N_per_um;
    sgs_gain_[i] = model_.sgs_gain_per_elongation[i];
  }
  sgs_beta_ = 1.0 - std::exp(-2.0 * std::numbers::pi * p.sgs.bandwidth_Hz * model_.physics_step_s);
  sgs_beta_tick_ =
      1.0 - std::exp(-2.0 * std::numbers::pi * p.sgs.bandwidth_Hz * model_.control_period_s);
  ai_noise_V_ =
      std::hypot(p.sgs.noise_nm_rms * 1e-3 / model_.sgs_nominal_um_per_V, p.daq.ai_noise_V_rms);
  lsb_V_ = daq_lsb_V(p.daq);
  inv_lsb_V_ = 1.0 / lsb_V_;  // cheaper than dividing; can differ only at an exact midpoint
  code_max_ = std::ldexp(1.0, static_cast<int>(p.daq.resolution_bits) - 1) - 1.0;
  code_min_ = -code_max_ - 1.0;
  mechanics_ = model_.mechanics;
  update_mean_point_weights();
  force_N_.assign(model_.substeps, {0.0, 0.0, 0.0});  // the one allocation, at set-up
  ifm_countdown_ = model_.interferometer_every;
  for (std::size_t i = 0; i < 3; ++i)
    sgs_last_V_[i] = p.sgs.offset_V[i];
  update_truth(Vec3{0.0, 0.0, 0.0});
}

// daq_quantize_V with the constants kept (a product for the quotient: the same code except, at
// most, exactly at a rounding midpoint).
double Twin::quantize_V(double v) const noexcept {
  double c = std::nearbyint(v * inv_lsb_V_);
  if (!(c == c))
    c = 0.0;
  c = c < code_min_ ? code_min_ : (c > code_max_ ? code_max_ : c);
  return c * lsb_V_;
}

AoStatus Twin::write_ao(const Vec3& ao_V) noexcept {
  const double range = model_.params.daq.range_V;
  AoStatus status = AoStatus::kOk;
  for (std::size_t i = 0; i < 3; ++i) {
    const double v = ao_V[i];
    if (!std::isfinite(v)) {
      status = AoStatus::kInvalid;
      continue;
    }
    if ((v > range || v < -range) && status == AoStatus::kOk)
      status = AoStatus::kClamped;
    ao_V_[i] = quantize_V(v);
  }
  return status;
}

void Twin::advance() noexcept {
  const TwinModel& m = model_;
  const std::size_t n = m.substeps;
  const double beta = sgs_beta_;
  const double gain_V = m.params.amplifier.gain;
  const double inv_n = 1.0 / static_cast<double>(n);

  // Pass 1, one stack at a time (few live values, so they stay in registers): amplifier,
  // hysteresis, free elongation and its conditioner-filtered copy, and the stack force for every
  // physics step of the period. The amplifier's output runs monotonically toward its held
  // target, so the hysteresis is evaluated along a monotone sweep (hysteresis.hpp, PlaySweep).
  const Amplifier amp = m.amplifier;
  double y_mean[3];
  for (std::size_t c = 0; c < 3; ++c) {
    const double in = faults_[c].amplifier_failed ? 0.0 : ao_V_[c];
    double v = amp_V_[c];
    PlaySweep sweep(m.hysteresis, play_[c], gain_V * in > v);
    const double g = m.stroke_gain_um[c], creep = creep_out_[c], k = ks_[c], r = hertz_r_um_[c];
    double y_sum = 0.0, xf = free_um_[c], f = filtered_free_um_[c];
    for (std::size_t s = 0; s < n; ++s) {
      v = amp.step(v, in);
      const double y = sweep.at(v);
      y_sum += y;
      xf = g * (y + creep);
      f += beta * (xf - f);
      force_N_[s][c] = k * (xf - r);
    }
    sweep.commit(play_[c]);
    amp_V_[c] = v;
    free_um_[c] = xf;
    filtered_free_um_[c] = f;
    y_mean[c] = y_sum * inv_n;
  }

  // Pass 2: the legs and plate, the filtered modal coordinates, the interferometer's samples.
  const LinearMechanics mech = mechanics_;
  MechanicsState ms = mech_;
  double fm0 = filtered_modes_[0], fm1 = filtered_modes_[2], fm2 = filtered_modes_[4];
  std::size_t countdown = ifm_countdown_;
  bool pending_end_sample = false;
  const double w0 = mean_point_modal_[0], w1 = mean_point_modal_[1], w2 = mean_point_modal_[2];
  double z_max = -std::numeric_limits<double>::infinity();
  double z_min = std::numeric_limits<double>::infinity();
  double z_sum = 0.0;
  const double t0 = static_cast<double>(tick_) * m.control_period_s;
  for (std::size_t s = 0; s < n; ++s) {
    mech.step(ms, force_N_[s]);
    const double z_mean = w0 * ms[0] + w1 * ms[2] + w2 * ms[4];
    z_max = z_mean > z_max ? z_mean : z_max;
    z_min = z_mean < z_min ? z_mean : z_min;
    z_sum += z_mean;
    fm0 += beta * (ms[0] - fm0);
    fm1 += beta * (ms[2] - fm1);
    fm2 += beta * (ms[4] - fm2);
    if (--countdown == 0) {
      countdown = m.interferometer_every;
      if (s + 1 == n) {
        pending_end_sample = true;  // at the period's end: sampled below, temperatures shared
      } else {
        const double t = t0 + static_cast<double>(s + 1) * m.physics_step_s;
        sample_interferometer(mech.displacement_um(ms), t, lab_.drift_um(lab_state_));
      }
    }
  }
  mech_ = ms;
  filtered_modes_[0] = fm0;
  filtered_modes_[2] = fm1;
  filtered_modes_[4] = fm2;
  ifm_countdown_ = countdown;
  const Vec3 x = mechanics_.displacement_um(mech_);
  for (std::size_t i = 0; i < 3; ++i) {
    const double r = hertz_r_um_[i];
    const double f = ks_[i] * (free_um_[i] - r - x[i]);  // the contact's force increment
    elongation_um_[i] = free_um_[i] - ks_over_ka_[i] * (free_um_[i] - r - x[i]);
    filtered_hertz_r_um_[i] += sgs_beta_tick_ * (r - filtered_hertz_r_um_[i]);
    truth_.contact_force_N[i] = m.contact_preload_N + f;
    truth_.contact_residual_um[i] = r;
    // For the next period, from the mechanism's force k_m x (the contact's force in statics):
    // the leg moves smoothly, while k_s (x_free - r - x) rings with every amplifier step.
    if (m.contact_hertz)
      hertz_r_um_[i] = m.hertz(m.mechanism_stiffness_N_per_um * x[i]);
  }
  ++tick_;
  for (std::size_t i = 0; i < 3; ++i) {
    creep_out_[i] = m.creep.update(creep_[i], y_mean[i]);
    if (m.params.sgs.gauge_creep_fraction != 0.0)
      gauge_out_[i] = m.gauge_creep.update(gauge_creep_[i], elongation_um_[i]);
  }
  const double t = static_cast<double>(tick_) * m.control_period_s;
  // Per tick, in this order: the lab (1 deviate), the interferometer (3 per sample), the
  // excitation drift and each channel's zero flicker (the terms due), the AI (3).
  lab_.update(lab_state_, rng_);
  cavity_.update(cavity_state_, lab_, lab_state_, cavity_rng_);
  const double drift_um = lab_.drift_um(lab_state_);
  if (pending_end_sample)
    sample_interferometer(x, t, drift_um);
  truth_.interferometer_drift_nm = 1e3 * drift_um;
  sample_ai(lab_.structure_change_K(lab_state_));
  update_truth(x);
  truth_.period_max_mean_points_um = z_max;
  truth_.period_min_mean_points_um = z_min;
  truth_.period_avg_mean_points_um = z_sum / static_cast<double>(n);
}

void Twin::update_mean_point_weights() {
  // mean(P) = c . x with c_i = mean_j w_ji (barycentric rows), and x = Phi eta.
  const control::Mat3& w = model_.geometry.barycentric;
  const Eigen::Matrix3d phi = mechanics_.mode_shapes();
  for (Eigen::Index r = 0; r < 3; ++r) {
    double v = 0.0;
    for (Eigen::Index i = 0; i < 3; ++i) {
      const auto iu = static_cast<std::size_t>(i);
      v += (w[0][iu] + w[1][iu] + w[2][iu]) / 3.0 * phi(i, r);
    }
    mean_point_modal_[static_cast<std::size_t>(r)] = v;
  }
}

void Twin::sample_ai(double structure_change_K) noexcept {
  const TwinParams& p = model_.params;
  const SgsParams& sgs = p.sgs;
  const double drift_um = sgs.zero_drift_nm_per_K * 1e-3 * structure_change_K;
  const double nl_V = sgs.nonlinearity_fraction * sgs.full_scale_V;
  const double inv_scale = 1.0 / model_.sgs_nominal_um_per_V;
  const Vec3 fx = mechanics_.displacement_um(filtered_modes_);  // the filtered x
  const double delta = model_.sgs_excitation_drift.update(excitation_, tick_, rng_);
  truth_.sgs_excitation_drift_ppm = 1e6 * delta;
  for (std::size_t i = 0; i < 3; ++i) {
    const double z_nm = model_.sgs_zero_flicker.update(zero_flicker_[i], tick_, rng_);
    truth_.sgs_zero_flicker_nm[i] = z_nm;
    truth_.gauge_creep_um[i] = gauge_out_[i];
  }
  for (std::size_t i = 0; i < 3; ++i) {
    const double filtered_e =
        filtered_free_um_[i] -
        ks_over_ka_[i] * (filtered_free_um_[i] - filtered_hertz_r_um_[i] - fx[i]);
    const double r_um = sgs_gain_[i] * (1.0 + delta) * (filtered_e - gauge_out_[i]) + drift_um +
                        1e-3 * truth_.sgs_zero_flicker_nm[i];
    const double v_lin = r_um * inv_scale;
    double v = sgs.offset_V[i] + v_lin +
               nl_V * sgs_nonlinearity_shape(sgs.nonlinearity_shape, v_lin / sgs.full_scale_V);
    // One deviate per channel and sample carries the conditioner's and the ADC's noise (both
    // white at the sample rate, so their sum is one normal of the combined variance).
    const double noise = ai_noise_V_ * rng_.normal();
    const ChannelFault& f = faults_[i];
    if (f.sgs_open)
      v = 1.2 * sgs.full_scale_V;
    else if (f.sgs_stuck)
      v = sgs_last_V_[i];
    sgs_last_V_[i] = v;
    double ai = quantize_V(v + noise + f.adc_spike_V);
    faults_[i].adc_spike_V = 0.0;
    if (f.adc_nan)
      ai = std::numeric_limits<double>::quiet_NaN();
    ai_V_[i] = ai;
    truth_.sgs_V[i] = v + noise;
  }
}

void Twin::sample_interferometer(const Vec3& x_um, double t_s, double drift_um) noexcept {
  const InterferometerParams& p = model_.params.interferometer;
  const control::Mat3& w = model_.geometry.barycentric;
  const double res_um = p.resolution_nm * 1e-3;
  const double cyclic_um = p.cyclic_error_nm * 1e-3;
  const double k_cyclic = 4.0 * std::numbers::pi / (p.wavelength_nm * 1e-3);
  for (std::size_t j = 0; j < 3; ++j) {
    const double z = w[j][0] * x_um[0] + w[j][1] * x_um[1] + w[j][2] * x_um[2];
    double m = ifm_scale_ * z + drift_um + p.noise_nm_rms * 1e-3 * rng_.normal();
    if (cyclic_um != 0.0)
      m += cyclic_um * std::sin(k_cyclic * z);
    // The XL-80 counts in whole resolution steps: each sample is quantized, and the static mode
    // averages the quantized samples (then rounds the mean to the resolution again).
    ifm_.dynamic_um[j] = interferometer_quantize(m, res_um);
    static_sum_[j] += ifm_.dynamic_um[j];
  }
  ifm_.dynamic_time_s = t_s;
  if (++static_n_ == model_.interferometer_static_samples) {
    for (std::size_t j = 0; j < 3; ++j) {
      ifm_.static_um[j] =
          interferometer_static_reading(static_sum_[j], static_cast<double>(static_n_), res_um);
      static_sum_[j] = 0.0;
    }
    static_n_ = 0;
    ifm_.static_time_s = t_s;
    ++ifm_.static_count;
  }
}

void Twin::update_truth(const Vec3& x_um) noexcept {
  const TwinModel& m = model_;
  TwinTruth& t = truth_;
  t.time_s = static_cast<double>(tick_) * m.control_period_s;
  t.ao_V = ao_V_;
  t.amplifier_V = amp_V_;
  t.free_elongation_um = free_um_;
  t.stack_elongation_um = elongation_um_;
  t.leg_um = x_um;
  const Vec3 pose = control::multiply(m.legs_to_pose, x_um);
  t.plate_z_um = pose[0];
  t.theta_x_urad = pose[1];
  t.theta_y_urad = pose[2];
  t.points_um = control::multiply(m.geometry.barycentric, x_um);
  t.air_temperature_C = lab_.air_C(lab_state_);
  t.structure_temperature_C = lab_.structure_C(lab_state_);
  t.air_pressure_Pa = cavity_.pressure_Pa(cavity_state_);
  t.cavity_drift_nm = cavity_state_.drift_nm;
  t.cavity_path_nm = 1000.0 * t.plate_z_um + t.cavity_drift_nm;
}

void Twin::set_fault(std::size_t channel, const ChannelFault& fault) {
  if (channel >= 3)
    throw std::invalid_argument("twin: fault channel must be 0, 1 or 2");
  if (!(fault.stack_stiffness_scale > 0.0) || !std::isfinite(fault.stack_stiffness_scale))
    throw std::invalid_argument("twin: stack_stiffness_scale must be positive");
  const bool restiffen = fault.stack_stiffness_scale != faults_[channel].stack_stiffness_scale;
  faults_[channel] = fault;
  if (!restiffen)
    return;
  std::array<double, 3> k{};
  for (std::size_t i = 0; i < 3; ++i) {
    const double ka = model_.actuator_stiffness_N_per_um * faults_[i].stack_stiffness_scale;
    ks_[i] = series_stiffness_N_per_um(ka, model_.contact_stiffness_N_per_um);
    ks_over_ka_[i] = ks_[i] / ka;
    k[i] = model_.mechanism_stiffness_N_per_um + ks_[i];
  }
  // The modal coordinates change with the modes: carry the physical displacements, velocities
  // and filtered displacements over (x = Phi eta, so eta = Phi^-1 x).
  const Vec3 x = mechanics_.displacement_um(mech_);
  const Vec3 v = mechanics_.velocity_um_per_s(mech_);
  const Vec3 fx = mechanics_.displacement_um(filtered_modes_);
  mechanics_ = make_leg_plate_mechanics(model_, k);
  update_mean_point_weights();
  const Eigen::Matrix3d phi_inv = mechanics_.mode_shapes().inverse();
  const Eigen::Vector3d eta = phi_inv * Eigen::Vector3d(x[0], x[1], x[2]);
  const Eigen::Vector3d eta_dot = phi_inv * Eigen::Vector3d(v[0], v[1], v[2]);
  const Eigen::Vector3d eta_f = phi_inv * Eigen::Vector3d(fx[0], fx[1], fx[2]);
  for (Eigen::Index r = 0; r < 3; ++r) {
    const auto i = static_cast<std::size_t>(2 * r);
    mech_[i] = eta(r);
    mech_[i + 1] = eta_dot(r);
    filtered_modes_[i] = eta_f(r);
    filtered_modes_[i + 1] = 0.0;
  }
}

}  // namespace piezoshift::plant
