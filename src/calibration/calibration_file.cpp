#include "piezoshift/calibration/calibration_file.hpp"

#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/config_file.hpp"

namespace piezoshift::calibration {

namespace {

[[noreturn]] void fail(const io::ConfigFile& file, std::string_view section, std::string_view key,
                       const std::string& why) {
  throw core::InputError(fmt::format("{}: [{}] {}: {}", file.source(), section, key, why));
}

void read_improved(const io::ConfigFile& file, control::ImprovedParams& im) {
  const io::ConfigSection s = file.section("improved");
  if (!s.read("sample_time_s", im.sample_time_s, core::Bounds::positive()))
    fail(file, "improved", "sample_time_s", "missing (kind = \"improved\" needs [improved])");
  std::int64_t delay = static_cast<std::int64_t>(im.reference_delay_ticks);
  s.read("reference_delay_ticks", delay,
         core::Bounds::closed(0.0, static_cast<double>(control::kMaxReferenceDelayTicks)));
  im.reference_delay_ticks = static_cast<std::size_t>(delay);
  s.read("correction_ki", im.correction_ki, core::Bounds::closed(0.0, 1.0));
  s.read("correction_ki_max", im.correction_ki_max, core::Bounds::closed(0.0, 1.0));
  s.read("correction_boost_error_um", im.correction_boost_error_um, core::Bounds::non_negative());
  s.read("correction_limit_um", im.correction_limit_um, core::Bounds::positive());
  std::vector<double> taps;
  if (s.read("shaper_taps", taps, control::kMaxShaperTaps, core::Bounds::closed(0.0, 1.0))) {
    im.shaper.taps = taps.size();
    im.shaper.weight = {};
    double sum = 0.0;
    for (std::size_t i = 0; i < taps.size(); ++i)
      sum += im.shaper.weight[i] = taps[i];
    if (std::fabs(sum - 1.0) > 1e-9)
      fail(file, "improved", "shaper_taps", fmt::format("must sum to 1 (they sum to {})", sum));
  }
  s.read("shaper_rate_um_per_s", im.shaper.rate_um_per_s, core::Bounds::positive());
  for (std::size_t i = 0; i < control::kChannels; ++i) {
    const std::string name = fmt::format("improved.channel{}", i + 1);
    const io::ConfigSection c = file.section(name);
    control::HysteresisCreepParams& m = im.model[i];
    c.read("offset_um", m.offset_um, core::Bounds::closed(-100.0, 100.0));
    if (!c.read("linear_weight", m.linear_weight, core::Bounds::closed(1e-3, 100.0)))
      fail(file, name, "linear_weight", "missing");
    std::vector<double> r, w, tau;
    c.read("thresholds_um", r, control::kMaxModelOperators, core::Bounds::positive());
    c.read("weights", w, control::kMaxModelOperators, core::Bounds::closed(0.0, 100.0));
    if (r.size() != w.size())
      fail(file, name, "weights", fmt::format("{} weights for {} thresholds", w.size(), r.size()));
    m.operators = r.size();
    for (std::size_t j = 0; j < r.size(); ++j) {
      m.threshold_um[j] = r[j];
      m.weight[j] = w[j];
    }
    c.read("creep_time_constants_s", tau, control::kMaxCreepTerms, core::Bounds::positive());
    m.creep_terms = tau.size();
    for (std::size_t k = 0; k < tau.size(); ++k)
      m.creep_time_constant_s[k] = tau[k];
    c.read("creep_gain", m.creep_gain, core::Bounds::closed(-0.05, 0.05));
  }
}

std::string number_list(const double* v, std::size_t n) {
  std::string out = "[";
  for (std::size_t i = 0; i < n; ++i)
    out += fmt::format("{}{}", i == 0 ? "" : ", ", v[i]);
  return out + "]";
}

std::string format_improved(const control::ImprovedParams& im) {
  std::string out =
      "\n[improved]  # the improved controller (docs/control.md), for one loop rate\n";
  out += fmt::format("sample_time_s = {}\n", im.sample_time_s);
  out += fmt::format("reference_delay_ticks = {}\n", im.reference_delay_ticks);
  out += fmt::format("correction_ki = {}  # per-sample at sample_time_s\n", im.correction_ki);
  out += fmt::format("correction_ki_max = {}\n", im.correction_ki_max);
  out += fmt::format("correction_boost_error_um = {}\n", im.correction_boost_error_um);
  out += fmt::format("correction_limit_um = {}\n", im.correction_limit_um);
  out += "shaper_taps = " + number_list(im.shaper.weight.data(), im.shaper.taps) + "\n";
  out += fmt::format("shaper_rate_um_per_s = {}\n", im.shaper.rate_um_per_s);
  for (std::size_t i = 0; i < control::kChannels; ++i) {
    const control::HysteresisCreepParams& m = im.model[i];
    out += fmt::format("\n[improved.channel{}]  # gauge um from command um\n", i + 1);
    out += fmt::format("offset_um = {}\n", m.offset_um);
    out += fmt::format("linear_weight = {}\n", m.linear_weight);
    out += "thresholds_um = " + number_list(m.threshold_um.data(), m.operators) + "\n";
    out += "weights = " + number_list(m.weight.data(), m.operators) + "\n";
    out +=
        "creep_time_constants_s = " + number_list(m.creep_time_constant_s.data(), m.creep_terms) +
        "\n";
    out += fmt::format("creep_gain = {}\n", m.creep_gain);
  }
  return out;
}

}  // namespace

void read_controller_section(const io::ConfigFile& file, control::SemiClosedLoopParams& params) {
  const io::ConfigSection c = file.section("controller");
  c.read("kp", params.gains.kp, core::Bounds::non_negative());
  c.read("ki", params.gains.ki, core::Bounds::non_negative());
  c.read("kd", params.gains.kd, core::Bounds::non_negative());
  c.read("gains_sample_time_s", params.gains_sample_time_s, core::Bounds::positive());
  std::array<double, 4> p{params.polynomial.p3, params.polynomial.p2, params.polynomial.p1,
                          params.polynomial.p0};
  if (c.read("p", p))
    params.polynomial = control::CubicPolynomial{p[0], p[1], p[2], p[3]};
  c.read("A", params.matrix.a);
  std::string kind = "paper";
  if (c.read("kind", kind)) {
    if (kind == "improved")
      params.kind = control::ControllerKind::kImproved;
    else if (kind == "paper")
      params.kind = control::ControllerKind::kPaper;
    else
      fail(file, "controller", "kind", "expected \"paper\" or \"improved\"");
  }
  if (params.kind == control::ControllerKind::kImproved)
    read_improved(file, params.improved);
}

control::SemiClosedLoopParams load_calibration_file(const std::string& path,
                                                    std::optional<double>* travel_z_max_um,
                                                    std::optional<double>* travel_z_min_um) {
  const io::ConfigFile file = io::ConfigFile::load(path);
  control::SemiClosedLoopParams params;
  read_controller_section(file, params);
  double z_max_um = 0.0, z_min_um = 0.0;
  const bool has_max = file.section("travel").read("z_max_um", z_max_um, core::Bounds::positive());
  const bool has_min =
      file.section("travel").read("z_min_um", z_min_um, core::Bounds::non_negative());
  file.reject_unknown();
  if (has_min && has_max && !(z_min_um < z_max_um))
    throw core::InputError(fmt::format("{}: [travel] z_min_um = {} must be below z_max_um = {}",
                                       path, z_min_um, z_max_um));
  if (travel_z_max_um != nullptr)
    *travel_z_max_um = has_max ? std::optional<double>(z_max_um) : std::nullopt;
  if (travel_z_min_um != nullptr)
    *travel_z_min_um = has_min ? std::optional<double>(z_min_um) : std::nullopt;
  return params;
}

std::string format_calibration(const control::SemiClosedLoopParams& params,
                               const std::string& header, std::optional<double> travel_z_max_um,
                               std::optional<double> travel_z_min_um) {
  std::string out;
  std::istringstream lines(header);
  for (std::string line; std::getline(lines, line);)
    out += "# " + line + "\n";
  const auto& g = params.gains;
  const auto& p = params.polynomial;
  const auto& a = params.matrix.a;
  out += "\n[controller]\n";
  out += fmt::format("kp = {}  # per-sample gains, Eq. 7\n", g.kp);
  out += fmt::format("ki = {}\n", g.ki);
  out += fmt::format("kd = {}\n", g.kd);
  out += fmt::format("gains_sample_time_s = {}\n", params.gains_sample_time_s);
  out +=
      fmt::format("p = [{}, {}, {}, {}]  # [p3, p2, p1, p0], Eq. 8, um\n", p.p3, p.p2, p.p1, p.p0);
  out += "A = [";
  for (std::size_t r = 0; r < 3; ++r) {
    out += fmt::format("{}[{}, {}, {}]{}", r == 0 ? "" : "     ", a[r][0], a[r][1], a[r][2],
                       r == 2 ? "]  # S = A Z_S, Eq. 8\n" : ",\n");
  }
  if (params.kind == control::ControllerKind::kImproved) {
    out += "kind = \"improved\"\n";
    out += format_improved(params.improved);
  }
  if (travel_z_max_um) {
    out += "\n[travel]\n";
    out += fmt::format(
        "z_max_um = {}  # the travel one move from rest reaches (Section 4.1's search, then "
        "single moves)\n",
        *travel_z_max_um);
    if (travel_z_min_um)
      out += fmt::format("z_min_um = {}  # the lowest Z a move from the top reaches\n",
                         *travel_z_min_um);
  }
  return out;
}

void write_calibration_file(const std::string& path, const control::SemiClosedLoopParams& params,
                            const std::string& header, std::optional<double> travel_z_max_um,
                            std::optional<double> travel_z_min_um) {
  io::write_file_atomically(path,
                            format_calibration(params, header, travel_z_max_um, travel_z_min_um));
}

}  // namespace piezoshift::calibration
