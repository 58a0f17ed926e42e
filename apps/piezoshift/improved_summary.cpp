#include "improved_summary.hpp"

#include <vector>

#include <fmt/core.h>

#include "piezoshift/io/csv_writer.hpp"

namespace piezoshift::app {

nlohmann::json improved_json(const ImprovedSummary& s) {
  nlohmann::json j;
  nlohmann::json models = nlohmann::json::array();
  for (const auto& m : s.model)
    models.push_back({{"rms_residual_um", m.rms_residual_um},
                      {"delay_ticks", m.delay_ticks},
                      {"linear_weight", m.params.linear_weight},
                      {"creep_gain", m.params.creep_gain},
                      {"samples_fitted", m.samples_fitted}});
  j["models"] = models;
  j["mode_Hz"] = s.mode.mode_Hz;
  j["mode_sample_rate_Hz"] = s.mode.sample_rate_Hz;
  j["shaped"] = s.shaped;
  const control::ShaperParams& sh = s.controller.shaper;
  j["shaper_taps"] = std::vector<double>(sh.weight.begin(),
                                         sh.weight.begin() + static_cast<std::ptrdiff_t>(sh.taps));
  j["shaper_rate_um_per_s"] = sh.rate_um_per_s;
  j["correction_ki"] = s.controller.correction_ki;
  j["sample_time_s"] = s.controller.sample_time_s;
  return j;
}

void print_improved(const ImprovedSummary& s) {
  for (std::size_t i = 0; i < 3; ++i)
    fmt::print(
        "model {}  hysteresis + creep, rms residual {:.1f} nm, delay {} ticks, w0 {:.4f}, creep "
        "from {:.3g} s\n",
        i + 1, 1e3 * s.model[i].rms_residual_um, s.model[i].delay_ticks,
        s.model[i].params.linear_weight, s.model[i].params.creep_time_constant_s[0]);
  const control::ShaperParams& sh = s.controller.shaper;
  if (s.shaped)
    fmt::print("shaper   mode {:.0f} Hz as sampled at {:.0f} Hz; {} taps; rate limit {:.0f} um/s\n",
               s.mode.mode_Hz, s.mode.sample_rate_Hz, sh.taps, sh.rate_um_per_s);
  else
    fmt::print("shaper   no mode nulled ({}); rate limit {:.0f} um/s\n",
               s.mode.sample_rate_Hz > 0.0 ? "none the ring-down shows at this loop rate"
                                           : "no ring-down given",
               sh.rate_um_per_s);
}

void write_improved_records(const calibration::ImprovedCalibrationOutcome& ic,
                            const std::string& excitation_file, const std::string& mode_file) {
  {
    io::CsvWriter w(excitation_file,
                    {"t_s", "u1_um", "u2_um", "u3_um", "sgs1_um", "sgs2_um", "sgs3_um"}, 12);
    w.comment("improved calibration stage 4: the open-loop excitation, one row per tick");
    for (std::size_t k = 0; k < ic.record_t_s.size(); ++k)
      w.row({ic.record_t_s[k], ic.record_command_um[0][k], ic.record_command_um[1][k],
             ic.record_command_um[2][k], ic.record_gauge_um[0][k], ic.record_gauge_um[1][k],
             ic.record_gauge_um[2][k]});
    w.close();
  }
  io::CsvWriter w(mode_file, {"t_s", "measured_um"}, 9);
  w.comment(fmt::format(
      "improved calibration stage 5: the interferometer (mean of P1..P3) after a small open-loop "
      "step, at {} Hz, t_s from the step",
      ic.mode.sample_rate_Hz));
  for (std::size_t k = 0; k < ic.mode_record_t_s.size(); ++k)
    w.row({ic.mode_record_t_s[k], ic.mode_record_um[k]});
  w.close();
}

}  // namespace piezoshift::app
