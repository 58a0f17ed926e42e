#include "piezoshift/experiments/phase_step.hpp"

#include <cmath>
#include <deque>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>

#include "bench_checks.hpp"

namespace piezoshift::experiments {

using control::Vec3;

double exposure_settling_time_s(const std::vector<double>& time_s,
                                const std::vector<double>& value_nm, double target_nm,
                                double tolerance_nm) {
  if (time_s.empty() || time_s.size() != value_nm.size())
    throw std::invalid_argument("exposure_settling_time_s: empty or unequal series");
  if (std::fabs(value_nm.back() - target_nm) > tolerance_nm)
    return std::numeric_limits<double>::infinity();
  for (std::size_t k = value_nm.size(); k-- > 0;) {
    if (std::fabs(value_nm[k] - target_nm) > tolerance_nm)
      return time_s[k];
  }
  return 0.0;
}

namespace {

void check_options(const PhaseStepOptions& o) {
  if (!(o.wavelength_nm > 0.0 && o.start_um >= 0.0 && o.settle_s >= 0.0 && o.hold_s > 0.0 &&
        o.record_s > 0.0 && o.exposure_s > 0.0 && o.tolerance_nm > 0.0 &&
        o.target_tolerance_nm > 0.0))
    throw std::invalid_argument("phase step: every duration, length and tolerance must be > 0");
}

// Control periods per exposure; refused unless the exposure is a whole number of them.
std::size_t periods_per_exposure(const PhaseStepOptions& o, double sample_time_s) {
  const double periods = o.exposure_s / sample_time_s;
  const auto per_exposure = static_cast<std::size_t>(std::llround(periods));
  if (per_exposure < 1 || std::fabs(periods - static_cast<double>(per_exposure)) > 1e-6)
    throw std::invalid_argument(fmt::format(
        "phase step: the exposure ({:g} s) must be a whole number of control periods ({:g} s)",
        o.exposure_s, sample_time_s));
  return per_exposure;
}

// One exposure mean per tick: a boxcar over the last per_exposure period averages of the plate's
// true position.
class ExposureWindow {
 public:
  explicit ExposureWindow(std::size_t per_exposure) : per_exposure_(per_exposure) {}

  //! Adds this tick's period average; returns the mean over the window [nm].
  double add(const rig::Bench& b) {
    const double v = 1e3 * b.twin().truth().period_avg_mean_points_um;
    window_.push_back(v);
    sum_ += v;
    if (window_.size() > per_exposure_) {
      sum_ -= window_.front();
      window_.pop_front();
    }
    return sum_ / static_cast<double>(window_.size());
  }
  bool full() const { return window_.size() == per_exposure_; }

 private:
  std::size_t per_exposure_;
  std::deque<double> window_;
  double sum_ = 0.0;
};

// The hold's exposure means about their least-squares line (drift is not jitter).
struct HoldTrend {
  double mean_t_s = 0.0, mean_nm = 0.0, slope_nm_per_s = 0.0;
  double jitter_nm_rms = 0.0;  //!< rms of the residuals, n - 2 degrees of freedom

  double at(double t_s) const { return mean_nm + slope_nm_per_s * (t_s - mean_t_s); }
};

HoldTrend hold_trend(const std::vector<double>& t_s, const std::vector<double>& v_nm) {
  HoldTrend h;
  const double n = static_cast<double>(t_s.size());
  double mt = 0.0, mv = 0.0;
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    mt += t_s[k] / n;
    mv += v_nm[k] / n;
  }
  double stt = 0.0, stv = 0.0;
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    stt += (t_s[k] - mt) * (t_s[k] - mt);
    stv += (t_s[k] - mt) * (v_nm[k] - mv);
  }
  const double slope = stt > 0.0 ? stv / stt : 0.0;
  double ss = 0.0;
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    const double e = v_nm[k] - (mv + slope * (t_s[k] - mt));
    ss += e * e;
  }
  h.mean_t_s = mt;
  h.mean_nm = mv;
  h.slope_nm_per_s = slope;
  h.jitter_nm_rms = t_s.size() > 2 ? std::sqrt(ss / (n - 2.0)) : 0.0;
  return h;
}

struct Run {
  std::vector<double> time_s, mean_nm;
  double hold_jitter_nm_rms = 0.0;
};

// One run: settle at start_um, hold (its exposure means' trend line gives the level before),
// then drive to target_um and record. A PID at its limit before a step fails validity.
Run run_once(rig::Bench& on, const PhaseStepOptions& o, std::size_t per_exposure, double target_um,
             rig::Validity& validity) {
  const double z0_um = o.start_um;
  on.drive_points(Vec3{z0_um, z0_um, z0_um});
  on.run(o.settle_s);
  ExposureWindow window(per_exposure);

  // The hold: exposure means (once the window is full) and their least-squares line.
  std::vector<double> hold_t, hold_v;
  const double t_hold = on.time_s();
  on.run(o.hold_s, [&](const rig::Bench& b) {
    const double v = window.add(b);
    if (window.full()) {
      hold_t.push_back(b.time_s() - t_hold);
      hold_v.push_back(v);
    }
  });
  const HoldTrend trend = hold_trend(hold_t, hold_v);
  Run run;
  run.hold_jitter_nm_rms = trend.jitter_nm_rms;
  const double t_step = on.time_s();
  const double level_nm = trend.at(t_step - t_hold);
  if (target_um != z0_um)
    if (const std::string sat = detail::saturation_problem(on, z0_um); !sat.empty())
      validity.fail(sat + " before the step");
  on.drive_points(Vec3{target_um, target_um, target_um});
  on.run(o.record_s, [&](const rig::Bench& b) {
    run.time_s.push_back(b.time_s() - t_step);
    run.mean_nm.push_back(window.add(b) - level_nm);
  });
  return run;
}

// The stepped run's settling time and final error, and whether it made the step asked for.
void judge_step(PhaseStepResult& r, const rig::Bench& bench, const PhaseStepOptions& o,
                std::size_t per_exposure, double z1_um) {
  r.settling_time_s =
      exposure_settling_time_s(r.time_s, r.exposure_mean_nm, r.step_nm, o.tolerance_nm);
  const std::size_t tail = std::min<std::size_t>(10 * per_exposure, r.exposure_mean_nm.size());
  double final_nm = 0.0;
  for (std::size_t k = r.exposure_mean_nm.size() - tail; k < r.exposure_mean_nm.size(); ++k)
    final_nm += r.exposure_mean_nm[k] / static_cast<double>(tail);
  r.final_error_nm = final_nm - r.step_nm;
  detail::check_fault(bench, r.validity, "during the phase step");
  if (const std::string sat = detail::saturation_problem(bench, z1_um); !sat.empty())
    r.validity.fail(sat + " at the end of the record");
  if (std::fabs(r.final_error_nm) > o.target_tolerance_nm)
    r.validity.fail(fmt::format(
        "the phase step did not reach its target: {:.2f} nm for {:.2f} nm (tolerance {:g} nm)",
        final_nm, r.step_nm, o.target_tolerance_nm));
}

// The same run without the step: the twin's noise and drift do not depend on the drive, so
// the difference is the controller's own step (the excitation drift scales with position:
// 79 nm in 5 um changes it by 1.6 %, well below the figures' resolution).
void compare_with_still_run(PhaseStepResult& r, const config::ProjectConfig& config,
                            const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                            const PhaseStepOptions& o, std::size_t per_exposure) {
  rig::Bench still_bench(config, controller, seed, o.bench);
  const Run still = run_once(still_bench, o, per_exposure, o.start_um, r.validity);
  r.simulated_time_s += still_bench.time_s();
  detail::check_fault(still_bench, r.validity, "during the phase step's run without the step");
  r.still_exposure_mean_nm = still.mean_nm;
  std::vector<double> own(r.exposure_mean_nm.size());
  for (std::size_t k = 0; k < own.size(); ++k) {
    own[k] = r.exposure_mean_nm[k] - still.mean_nm[k];
    r.still_wander_nm = std::max(r.still_wander_nm, std::fabs(still.mean_nm[k]));
  }
  r.own_settling_time_s = exposure_settling_time_s(r.time_s, own, r.step_nm, o.tolerance_nm);
}

}  // namespace

PhaseStepResult run_phase_step(const config::ProjectConfig& config,
                               const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                               const PhaseStepOptions& o, const rig::Progress& progress) {
  check_options(o);
  PhaseStepResult r;
  r.step_nm = o.step_nm();
  const double z1_um = o.start_um + 1e-3 * r.step_nm;
  rig::Bench bench(config, controller, seed, o.bench);
  const std::size_t per_exposure = periods_per_exposure(o, bench.sample_time_s());

  const Run stepped = run_once(bench, o, per_exposure, z1_um, r.validity);
  r.time_s = stepped.time_s;
  r.exposure_mean_nm = stepped.mean_nm;
  r.hold_jitter_nm_rms = stepped.hold_jitter_nm_rms;
  r.simulated_time_s = bench.time_s();
  judge_step(r, bench, o, per_exposure, z1_um);
  compare_with_still_run(r, config, controller, seed, o, per_exposure);
  if (progress)
    progress(1, 1, "phase step");
  return r;
}

}  // namespace piezoshift::experiments
