#include "piezoshift/runtime/controller_config.hpp"

#include <array>

#include "piezoshift/io/config_file.hpp"

namespace piezoshift::runtime {

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

control::SemiClosedLoopParams load_controller_config(const std::string& path) {
  const io::ConfigFile file = io::ConfigFile::load(path);
  control::SemiClosedLoopParams params;
  read_controller_section(file, params);
  file.reject_unknown();
  return params;
}

}  // namespace piezoshift::runtime
