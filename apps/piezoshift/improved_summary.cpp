#include "improved_summary.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/csv_writer.hpp"
#include "piezoshift/io/input_file.hpp"

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
  j["command_slew_um_per_s"] = s.controller.command_slew_um_per_s;
  j["slew_approach_um"] = s.controller.slew_approach_um;
  if (s.large_move)
    j["large_move_trial"] = {
        {"tried", s.large_move->tried},
        {"not_tried", s.large_move->not_tried.empty() ? nlohmann::json(nullptr)
                                                      : nlohmann::json(s.large_move->not_tried)},
        {"slew_um_per_s", s.large_move->slew_um_per_s},
        {"slew_overshoot_pct", s.large_move->slew_overshoot_pct},
        {"shaper_overshoot_pct", s.large_move->shaper_overshoot_pct},
        {"slew_kept", s.large_move->slew_kept}};
  if (s.rate_verdict) {
    const calibration::RateVerdict& v = *s.rate_verdict;
    const auto number = [](double x) {
      return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
    };
    j["rate_verdict"] = {{"mode_Hz", v.mode_Hz},
                         {"loop_rate_Hz", v.loop_rate_Hz},
                         {"folded_Hz", v.folded_Hz},
                         {"phase_step_s", number(v.step_s)},
                         {"target_s", v.target_s},
                         {"mode_is_the_limit", v.mode_is_the_limit},
                         {"faster_rate_Hz", v.faster_rate_Hz},
                         {"faster_phase_step_s", v.faster_step_s},
                         {"text", v.text()}};
  }
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
  if (s.large_move && s.large_move->tried)
    fmt::print(
        "moves    > 2 um at the slew limit {}: an 11 um step overshoots {:.2f} % with it, {:.2f} "
        "% with the shaper alone\n",
        s.large_move->slew_kept ? "kept" : "turned off", s.large_move->slew_overshoot_pct,
        s.large_move->shaper_overshoot_pct);
  else if (s.large_move)
    fmt::print("moves    the slew path not tried: {}\n", s.large_move->not_tried);
  if (s.rate_verdict && s.rate_verdict->mode_is_the_limit)
    fmt::print("rate     {}\n", s.rate_verdict->text());
  else if (s.rate_verdict && s.rate_verdict->mode_Hz > 0.0)
    fmt::print(
        "rate     the plate's mode at {:.0f} Hz allows the lambda/8 step in {:.0f} ms at "
        "this loop's rate\n",
        s.rate_verdict->mode_Hz, 1e3 * s.rate_verdict->step_s);
}

namespace {

constexpr std::string_view kRowsKey = "rows = ";

// N of the first comment line "# rows = N", nullopt without one (a file another tool wrote).
std::optional<std::size_t> promised_rows(std::string_view text) {
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t nl = std::min(text.find('\n', pos), text.size());
    std::string_view line = text.substr(pos, nl - pos);
    pos = nl + 1;
    while (!line.empty() && (line.back() == '\r' || line.back() == ' '))
      line.remove_suffix(1);
    if (line.size() < 2 || line.substr(0, 2) != "# " || line.substr(2, kRowsKey.size()) != kRowsKey)
      continue;
    const std::string_view digits = line.substr(2 + kRowsKey.size());
    std::size_t n = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), n);
    if (ec == std::errc() && end == digits.data() + digits.size())
      return n;
  }
  return std::nullopt;
}

}  // namespace

void write_improved_records(const calibration::ImprovedCalibrationOutcome& ic,
                            const std::string& excitation_file, const std::string& mode_file) {
  constexpr auto kAtomic = io::CsvWriter::Mode::kReplaceAtomically;
  {
    io::CsvWriter w(excitation_file,
                    {"t_s", "u1_um", "u2_um", "u3_um", "sgs1_um", "sgs2_um", "sgs3_um"}, 12,
                    kAtomic);
    w.comment("improved calibration stage 4: the open-loop excitation, one row per tick");
    w.comment(fmt::format("{}{}", kRowsKey, ic.record_t_s.size()));
    for (std::size_t k = 0; k < ic.record_t_s.size(); ++k)
      w.row({ic.record_t_s[k], ic.record_command_um[0][k], ic.record_command_um[1][k],
             ic.record_command_um[2][k], ic.record_gauge_um[0][k], ic.record_gauge_um[1][k],
             ic.record_gauge_um[2][k]});
    w.close();
  }
  io::CsvWriter w(mode_file, {"t_s", "measured_um"}, 9, kAtomic);
  w.comment(fmt::format(
      "improved calibration stage 5: the interferometer (mean of P1..P3) after a small open-loop "
      "step, at {} Hz, t_s from the step",
      ic.mode.sample_rate_Hz));
  w.comment(fmt::format("{}{}", kRowsKey, ic.mode_record_t_s.size()));
  for (std::size_t k = 0; k < ic.mode_record_t_s.size(); ++k)
    w.row({ic.mode_record_t_s[k], ic.mode_record_um[k]});
  w.close();
}

io::CsvTable load_record(const std::string& path) {
  const std::string text = io::read_input_file(path, io::kMaxDataFileBytes);
  if (!text.empty() && text.back() != '\n')
    throw core::InputError(
        fmt::format("{}:{}: the last line has no line end: the file is cut short (truncated)", path,
                    std::count(text.begin(), text.end(), '\n') + 1));
  io::CsvTable t = io::CsvTable::parse(text, path);
  if (const std::optional<std::size_t> n = promised_rows(text); n && *n != t.rows())
    throw core::InputError(fmt::format(
        "{}: {} data rows where the file promises {} (# {}{}): the file is cut short (truncated)",
        path, t.rows(), *n, kRowsKey, *n));
  return t;
}

}  // namespace piezoshift::app
