// `piezoshift simulate`: runs the digital twin (docs/twin.md) open loop or with the paper's
// semi-closed-loop controller, through the loop `run` and `serve` ship (the simulated bench,
// rig/bench.hpp: DAQ read, controller, safety supervisor, DAQ write), and reports where
// the plate ended up, the target and the error. The controller is `run`'s: --calibration FILE,
// or else the twin calibrated first by the paper's procedure (loop_setup.hpp,
// procedures::resolve_calibration), so that the two commands agree. A supervisor fault ends the
// run's control (outputs ramp to 0 V) and the command exits with status 3, as `run` does.
//
//   piezoshift simulate --open-loop-volts 10,10,10 --duration-s 2
//   piezoshift simulate --step-um 11 --duration-s 1 --log step.csv --json
//   piezoshift simulate --profile profile.csv --duration-s 120 --seed 7 --config my.toml
//
// Per tick: Z_d from the mode, then the shipping tick. The profile is `run`'s
// (runtime/setpoint_profile.hpp: t_s and zd_um or zd1_um..zd3_um, piecewise linear). The log has
// one row per control tick, in the column vocabulary of docs/files.md: the AI read and the AO
// written in it, and the truth and the interferometer's dynamic reading at the end of the period
// the AI closes.
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "physics_budget.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/csv_table.hpp"
#include "piezoshift/io/csv_writer.hpp"
#include "piezoshift/plant/simulation_cost.hpp"
#include "piezoshift/plant/twin.hpp"
#include "piezoshift/procedures/loop_setup.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"
#include "piezoshift/runtime/setpoint_profile.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {
namespace {

using Json = nlohmann::ordered_json;
using control::Vec3;

struct SimulateOptions {
  std::string config_path;  // empty: the built-in twin (configs/paper.toml's values)
  std::string calibration;  // empty: the twin calibrated first (closed loop)
  std::uint64_t seed = 1;
  double duration_s = 1.0;
  std::vector<double> open_loop_volts;
  std::optional<double> step_um;
  double step_at_s = 0.0;
  std::string profile_path;
  std::string log_path;
  bool json = false;
  double max_physics_steps = plant::kDefaultPhysicsStepBudget;
};

std::vector<std::string> log_columns(bool closed_loop) {
  std::vector<std::string> c{"t_s"};
  if (closed_loop) {
    for (const char* n :
         {"zd1_um", "zd2_um", "zd3_um", "s1_um", "s2_um", "s3_um", "u1_um", "u2_um", "u3_um"})
      c.emplace_back(n);
  }
  // clang-format off
  static constexpr const char* kTwinColumns[] = {
      "ao1_V",     "ao2_V",     "ao3_V",     "amp1_V",     "amp2_V",       "amp3_V",
      "sgs1_V",    "sgs2_V",    "sgs3_V",    "stack1_um",  "stack2_um",    "stack3_um",
      "leg1_um",   "leg2_um",   "leg3_um",   "plate_z_um", "theta_x_urad", "theta_y_urad",
      "truth1_um", "truth2_um", "truth3_um",
      "interferometer1_um", "interferometer2_um", "interferometer3_um"};
  // clang-format on
  for (const char* n : kTwinColumns)
    c.emplace_back(n);
  if (closed_loop)
    c.emplace_back("saturated_mask_bits");
  return c;
}

Vec3 difference(const Vec3& a, const Vec3& b) {
  return Vec3{a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

Json vec_json(const Vec3& v) {
  return Json::array({v[0], v[1], v[2]});
}

void check_options(const SimulateOptions& opt) {
  const int modes = (opt.open_loop_volts.empty() ? 0 : 1) + (opt.step_um ? 1 : 0) +
                    (opt.profile_path.empty() ? 0 : 1);
  if (modes != 1) {
    throw core::InputError("simulate: give exactly one of --open-loop-volts, --step-um, --profile");
  }
  if (!std::isfinite(opt.duration_s) || !(opt.duration_s > 0.0))
    throw core::InputError(fmt::format("--duration-s = {} must be positive", opt.duration_s));
  check_physics_budget(opt.max_physics_steps);
  if (!std::isfinite(opt.step_at_s) || opt.step_at_s < 0.0)
    throw core::InputError(fmt::format("--step-at-s = {} must be >= 0", opt.step_at_s));
  if (opt.step_um && !std::isfinite(*opt.step_um))
    throw core::InputError("--step-um must be a finite number");
  if (!opt.calibration.empty() && !opt.open_loop_volts.empty())
    throw core::InputError("--calibration: open loop (--open-loop-volts) runs no controller");
}

// The supervisor (the bench's, as `run`'s, with the config's [safety]) passes 0 to 10 DAQ volts by
// default (0 to 150 V at the stacks); anything else would be clamped there, so it is refused.
Vec3 open_loop_volts(const SimulateOptions& opt, const runtime::SafetyLimits& limits) {
  Vec3 open_loop{};
  for (std::size_t i = 0; i < 3; ++i) {
    const double v = opt.open_loop_volts[i];
    if (!std::isfinite(v) || v < limits.output_min_V || v > limits.output_max_V) {
      throw core::InputError(
          fmt::format("--open-loop-volts: V{} = {} is outside the supervisor's {} to {} V", i + 1,
                      v, limits.output_min_V, limits.output_max_V));
    }
    open_loop[i] = v;
  }
  return open_loop;
}

// The cost before the start: the duration and the config's rates together.
void check_cost(const SimulateOptions& opt, const config::ProjectConfig& config) {
  const plant::SimulationCost cost = plant::estimate_simulation_cost(config.twin, opt.duration_s);
  if (const std::string p =
          plant::simulation_budget_problem(cost, opt.max_physics_steps, "--max-physics-steps");
      !p.empty()) {
    throw core::InputError(
        fmt::format("--duration-s {} with physics_rate_Hz {} and sample_time_s {} ({}): {}",
                    opt.duration_s, config.twin.physics_rate_Hz, config.twin.daq.sample_time_s,
                    opt.config_path.empty() ? "built-in configuration" : opt.config_path, p));
  }
}

// One log row: the tick's signals and the twin's state at its end (log_columns' order).
void log_tick(io::CsvWriter& log, std::vector<double>& row, const rig::Bench& bench,
              bool closed_loop, const Vec3& zd) {
  const plant::Twin& twin = bench.twin();
  const runtime::CycleSample& c = bench.last_cycle();
  const control::ControllerOutput& out = c.controller;
  const plant::TwinTruth& s = twin.truth();
  const plant::InterferometerReading& r = twin.interferometer();
  row.clear();
  row.push_back(s.time_s);
  if (closed_loop) {
    row.insert(row.end(), zd.begin(), zd.end());
    row.insert(row.end(), out.target_um.begin(), out.target_um.end());
    row.insert(row.end(), out.command_um.begin(), out.command_um.end());
  }
  for (const Vec3* v : std::initializer_list<const Vec3*>{
           &c.supervisor.ao_V, &s.amplifier_V, &c.ai_V, &s.stack_elongation_um, &s.leg_um})
    row.insert(row.end(), v->begin(), v->end());
  row.push_back(s.plate_z_um);
  row.push_back(s.theta_x_urad);
  row.push_back(s.theta_y_urad);
  row.insert(row.end(), s.points_um.begin(), s.points_um.end());
  row.insert(row.end(), r.dynamic_um.begin(), r.dynamic_um.end());
  if (closed_loop)
    row.push_back(static_cast<double>(out.saturated_mask));
  log.row(row);
}

// What the run did, for the summary.
struct SimulateRun {
  std::uint64_t ticks = 0;
  double period_s = 0.0;
  std::uint64_t saturated_ticks = 0;
  Vec3 final_zd_um{};       // closed loop: Z_d at the last tick
  std::string calibration;  // closed loop: where the controller came from
};

int report(const SimulateOptions& opt, const config::ProjectConfig& config, const rig::Bench& bench,
           const SimulateRun& run) {
  const plant::Twin& twin = bench.twin();
  const bool closed_loop = opt.open_loop_volts.empty();
  const double period_s = run.period_s;

  const plant::TwinTruth& s = twin.truth();
  const plant::InterferometerReading& r = twin.interferometer();
  const plant::TwinModel& m = twin.model();
  const Vec3& ai = bench.last_cycle().ai_V;
  const runtime::FaultRecord& fault = bench.fault();
  const int status = bench.faulted() ? kExitFault : 0;
  const char* mode = !closed_loop ? "open_loop" : (opt.step_um ? "step" : "profile");
  if (opt.json) {
    Json j{{"mode", mode},
           {"config_file", opt.config_path.empty() ? Json(nullptr) : Json(opt.config_path)},
           {"seed", opt.seed},
           {"duration_s", static_cast<double>(run.ticks) * period_s},
           {"ticks", run.ticks},
           {"control_period_s", period_s},
           {"physics_rate_Hz", config.twin.physics_rate_Hz},
           {"final_plate_z_um", s.plate_z_um},
           {"final_theta_x_urad", s.theta_x_urad},
           {"final_theta_y_urad", s.theta_y_urad},
           {"final_points_um", vec_json(r.dynamic_um)},
           {"final_points_static_um", vec_json(r.static_um)},
           {"final_true_points_um", vec_json(s.points_um)},
           {"final_ao_V", vec_json(s.ao_V)},
           {"final_ai_V", vec_json(ai)},
           {"final_amplifier_V", vec_json(s.amplifier_V)},
           {"saturated_ticks", run.saturated_ticks},
           {"model",
            {{"contact_stiffness_N_per_um", m.contact_stiffness_N_per_um},
             {"contact_identified", m.contact_identified},
             {"mechanism_stiffness_N_per_um", m.mechanism_stiffness_N_per_um},
             {"loaded_modes_Hz",
              Json::array({m.loaded_modes_Hz[0], m.loaded_modes_Hz[1], m.loaded_modes_Hz[2]})},
             {"unloaded_mechanism_Hz", m.unloaded_mechanism_Hz},
             {"sgs_gain", vec_json(m.geometry.sgs_gain)}}}};
    j["fault"] = bench.faulted() ? Json{{"reason", runtime::to_string(fault.reason)},
                                        {"channel", fault.channel + 1},
                                        {"time_s", static_cast<double>(fault.tick) * period_s},
                                        {"value", fault.value},
                                        {"limit", fault.limit}}
                                 : Json(nullptr);
    if (opt.step_um) {
      j["step_um"] = *opt.step_um;
      j["step_at_s"] = opt.step_at_s;
    }
    if (closed_loop) {
      j["calibration"] = run.calibration;
      j["final_zd_um"] = vec_json(run.final_zd_um);
      j["final_error_um"] = vec_json(difference(r.dynamic_um, run.final_zd_um));
    }
    if (!opt.log_path.empty())
      j["log_file"] = opt.log_path;
    fmt::print("{}\n", j.dump(2));
    return status;
  }
  fmt::print("piezoshift simulate ({}), seed {}, {} ticks of {} s\n", mode, opt.seed, run.ticks,
             period_s);
  fmt::print("  plate Z at O          {:10.4f} um\n", s.plate_z_um);
  fmt::print("  tilt theta_x, theta_y {:10.3f} {:10.3f} urad\n", s.theta_x_urad, s.theta_y_urad);
  fmt::print("  points P1..P3 (true)  {:10.4f} {:10.4f} {:10.4f} um\n", s.points_um[0],
             s.points_um[1], s.points_um[2]);
  fmt::print("  interferometer        {:10.4f} {:10.4f} {:10.4f} um\n", r.dynamic_um[0],
             r.dynamic_um[1], r.dynamic_um[2]);
  if (closed_loop) {
    const Vec3& zd = run.final_zd_um;
    const Vec3 e = difference(r.dynamic_um, zd);
    fmt::print("  target Z_d            {:10.4f} {:10.4f} {:10.4f} um\n", zd[0], zd[1], zd[2]);
    fmt::print("  error (interf. - Z_d) {:10.4f} {:10.4f} {:10.4f} um\n", e[0], e[1], e[2]);
    fmt::print("  controller            {}\n", run.calibration);
  }
  fmt::print("  stack voltages        {:10.3f} {:10.3f} {:10.3f} V\n", s.amplifier_V[0],
             s.amplifier_V[1], s.amplifier_V[2]);
  if (closed_loop)
    fmt::print("  saturated ticks       {:10d}\n", run.saturated_ticks);
  if (!opt.log_path.empty())
    fmt::print("  log                   {}\n", opt.log_path);
  if (bench.faulted())
    fmt::print(stderr,
               "piezoshift: simulate: the safety supervisor tripped: {} on channel {} at {:.3f} s "
               "(value {:g}, limit {:g}); the outputs ramped to 0 V\n",
               runtime::to_string(fault.reason), fault.channel + 1,
               static_cast<double>(fault.tick) * period_s, fault.value, fault.limit);
  return status;
}

int run_simulate(const SimulateOptions& opt) {
  check_options(opt);
  runtime::InstallationConfig installation;
  if (!opt.config_path.empty())
    installation = runtime::load_installation_config(opt.config_path);
  const config::ProjectConfig& config = installation.project;
  SimulateRun run;
  run.period_s = config.twin.daq.sample_time_s;
  const double period_s = run.period_s;
  const bool closed_loop = opt.open_loop_volts.empty();
  const runtime::SafetyLimits& limits = installation.safety;
  const Vec3 open_loop = closed_loop ? Vec3{} : open_loop_volts(opt, limits);
  std::optional<runtime::SetpointProfile> profile;
  if (!opt.profile_path.empty())
    profile = runtime::SetpointProfile::load_csv(opt.profile_path);
  check_cost(opt, config);
  run.ticks = static_cast<std::uint64_t>(std::llround(opt.duration_s / period_s));
  if (run.ticks < 1)
    throw core::InputError(fmt::format(
        "--duration-s = {} is shorter than one control period ({} s)", opt.duration_s, period_s));
  work_begins();  // the twin's calibration, then the run

  // `run`'s controller: the file, or the twin calibrated first (open loop needs none).
  control::SemiClosedLoopParams cp;
  if (closed_loop) {
    const procedures::LoopCalibration lc = procedures::resolve_calibration(
        opt.calibration, "sim", config, opt.seed, period_s, opt.max_physics_steps);
    calibration::refuse_fringe_lock(lc, "simulate");
    cp = lc.params;
    run.calibration = lc.source;
  }
  cp.sample_time_s = period_s;  // the gains re-expressed at the twin's DAQ period
  std::unique_ptr<rig::Bench> made;
  try {
    rig::BenchOptions bo;
    bo.limits = limits;
    made = std::make_unique<rig::Bench>(config, cp, opt.seed, bo);
  } catch (const std::invalid_argument& e) {
    throw core::InputError(fmt::format(
        "{}: {}", opt.config_path.empty() ? "configuration" : opt.config_path, e.what()));
  }
  rig::Bench& bench = *made;

  std::unique_ptr<io::CsvWriter> log;
  if (!opt.log_path.empty()) {
    log = std::make_unique<io::CsvWriter>(opt.log_path, log_columns(closed_loop), 9);
    log->comment(fmt::format("piezoshift simulate: seed {}, config {}, {} s at {} s per tick",
                             opt.seed, opt.config_path.empty() ? "built-in" : opt.config_path,
                             opt.duration_s, period_s));
  }

  std::vector<double> row;
  for (std::uint64_t k = 0; k < run.ticks; ++k) {
    const double t = static_cast<double>(k) * period_s;
    Vec3 zd{};
    if (!closed_loop) {
      bench.drive_open_loop(open_loop);
    } else {
      if (opt.step_um) {
        const double z = t >= opt.step_at_s ? *opt.step_um : 0.0;
        zd = Vec3{z, z, z};
      } else {
        zd = profile->at(t);
      }
      bench.drive_points(zd);
    }
    bench.run(period_s);
    if (closed_loop)
      run.saturated_ticks += bench.last_cycle().controller.saturated_mask != 0 ? 1 : 0;
    run.final_zd_um = zd;
    if (log)
      log_tick(*log, row, bench, closed_loop, zd);
  }
  if (log)
    log->close();
  return report(opt, config, bench, run);
}

}  // namespace

void add_simulate_command(CLI::App& app, Action& action) {
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Run the digital twin open loop or closed loop with run's controller (docs/twin.md)");
  auto opt = std::make_shared<SimulateOptions>();
  cmd->add_option("--config", opt->config_path,
                  "TOML file (configs/paper.toml's sections; absent keys keep the paper's values)");
  cmd->add_option("--calibration", opt->calibration,
                  "closed loop: the controller's calibration file, as `run` reads (default: the "
                  "twin calibrated first by the paper's procedure)");
  cmd->add_option("--seed", opt->seed, "seed of the twin's random numbers (default 1)")
      ->check(whole_number(0, kAnyUnsigned));
  cmd->add_option("--duration-s", opt->duration_s, "simulated time [s] (default 1)");
  cmd->add_option("--open-loop-volts", opt->open_loop_volts,
                  "open loop: the three DAQ output volts V1,V2,V3 (x15 at the stacks)")
      ->expected(3)
      ->delimiter(',');
  cmd->add_option("--step-um", opt->step_um,
                  "closed loop: step of the three points' desired displacement Z_d [um]");
  cmd->add_option("--step-at-s", opt->step_at_s, "when the step is applied [s] (default 0)");
  cmd->add_option(
      "--profile", opt->profile_path,
      "closed loop: CSV t_s and zd_um (or zd1_um..zd3_um), piecewise linear, as `run` reads");
  cmd->add_option("--log", opt->log_path, "CSV log, one row per control tick");
  add_physics_budget_option(cmd, opt->max_physics_steps);
  cmd->add_flag("--json", opt->json, "print a JSON summary instead of the text one");
  cmd->callback([&action, opt] { action = [opt] { return run_simulate(*opt); }; });
}

}  // namespace piezoshift::app
