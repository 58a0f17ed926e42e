#include "piezoshift/calibration/calibration_file.hpp"

#include <array>
#include <sstream>

#include <fmt/core.h>

#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/config_file.hpp"
#include "piezoshift/io/input_error.hpp"

namespace piezoshift::calibration {

void read_controller_section(const io::ConfigFile& file, control::SemiClosedLoopParams& params) {
  const io::ConfigSection c = file.section("controller");
  c.read("kp", params.gains.kp, io::Bounds::non_negative());
  c.read("ki", params.gains.ki, io::Bounds::non_negative());
  c.read("kd", params.gains.kd, io::Bounds::non_negative());
  c.read("gains_sample_time_s", params.gains_sample_time_s, io::Bounds::positive());
  std::array<double, 4> p{params.polynomial.p3, params.polynomial.p2, params.polynomial.p1,
                          params.polynomial.p0};
  if (c.read("p", p))
    params.polynomial = control::CubicPolynomial{p[0], p[1], p[2], p[3]};
  c.read("A", params.matrix.a);
}

control::SemiClosedLoopParams load_calibration_file(const std::string& path,
                                                    std::optional<double>* travel_z_max_um,
                                                    std::optional<double>* travel_z_min_um) {
  const io::ConfigFile file = io::ConfigFile::load(path);
  control::SemiClosedLoopParams params;
  read_controller_section(file, params);
  double z_max_um = 0.0, z_min_um = 0.0;
  const bool has_max = file.section("travel").read("z_max_um", z_max_um, io::Bounds::positive());
  const bool has_min =
      file.section("travel").read("z_min_um", z_min_um, io::Bounds::non_negative());
  file.reject_unknown();
  if (has_min && has_max && !(z_min_um < z_max_um))
    throw io::InputError(fmt::format("{}: [travel] z_min_um = {} must be below z_max_um = {}", path,
                                     z_min_um, z_max_um));
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
  out += fmt::format("kp = {:.17g}  # per-sample gains, Eq. 7\n", g.kp);
  out += fmt::format("ki = {:.17g}\n", g.ki);
  out += fmt::format("kd = {:.17g}\n", g.kd);
  out += fmt::format("gains_sample_time_s = {:.17g}\n", params.gains_sample_time_s);
  out += fmt::format("p = [{:.17g}, {:.17g}, {:.17g}, {:.17g}]  # [p3, p2, p1, p0], Eq. 8, um\n",
                     p.p3, p.p2, p.p1, p.p0);
  out += "A = [";
  for (std::size_t r = 0; r < 3; ++r) {
    out += fmt::format("{}[{:.17g}, {:.17g}, {:.17g}]{}", r == 0 ? "" : "     ", a[r][0], a[r][1],
                       a[r][2], r == 2 ? "]  # S = A Z_S, Eq. 8\n" : ",\n");
  }
  if (travel_z_max_um) {
    out += "\n[travel]\n";
    out += fmt::format(
        "z_max_um = {:.17g}  # the travel one move from rest reaches (Section 4.1's search, then "
        "single moves)\n",
        *travel_z_max_um);
    if (travel_z_min_um)
      out += fmt::format("z_min_um = {:.17g}  # the lowest Z a move from the top reaches\n",
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
