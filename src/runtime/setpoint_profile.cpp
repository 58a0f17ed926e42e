#include "piezoshift/runtime/setpoint_profile.hpp"

#include <cmath>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/csv_table.hpp"

namespace piezoshift::runtime {

SetpointProfile SetpointProfile::step(double z_um, double max_z_um) {
  if (!(z_um >= 0.0 && z_um <= max_z_um)) {
    throw core::InputError(
        fmt::format("--step-um: {} um is outside [0, {}] um (the nominal stroke)", z_um, max_z_um));
  }
  return from_samples({0.0}, {Vec3{z_um, z_um, z_um}}, "--step-um", max_z_um);
}

SetpointProfile SetpointProfile::from_samples(std::vector<double> t_s, std::vector<Vec3> z_um,
                                              const std::string& source, double max_z_um) {
  if (t_s.empty() || t_s.size() != z_um.size())
    throw core::InputError(fmt::format("{}: a profile needs at least one sample", source));
  for (std::size_t i = 0; i < t_s.size(); ++i) {
    if (!std::isfinite(t_s[i]) || t_s[i] < 0.0)
      throw core::InputError(
          fmt::format("{}: sample {}: t_s = {} is not >= 0", source, i + 1, t_s[i]));
    if (i > 0 && !(t_s[i] > t_s[i - 1])) {
      throw core::InputError(fmt::format("{}: sample {}: t_s = {} does not increase (previous {})",
                                         source, i + 1, t_s[i], t_s[i - 1]));
    }
    for (double z : z_um[i]) {
      if (!(z >= 0.0 && z <= max_z_um)) {
        throw core::InputError(fmt::format("{}: sample {}: z = {} um is outside [0, {}] um", source,
                                           i + 1, z, max_z_um));
      }
    }
  }
  SetpointProfile p;
  p.t_s_ = std::move(t_s);
  p.z_um_ = std::move(z_um);
  return p;
}

SetpointProfile SetpointProfile::load_csv(const std::string& path, double max_z_um) {
  const io::CsvTable table = io::CsvTable::load(path);
  if (table.rows() == 0)
    throw core::InputError(fmt::format("{}: the profile has no data rows", path));
  const std::vector<double> t = table.column("t_s");
  std::vector<Vec3> z(t.size());
  // The column vocabulary of docs/files.md: zd_um for all three points, or zd1_um..zd3_um.
  if (table.has_column("zd_um")) {
    if (table.has_column("zd1_um"))
      throw core::InputError(
          fmt::format("{}: give either zd_um or zd1_um..zd3_um, not both", path));
    const std::vector<double> c = table.column("zd_um");
    for (std::size_t i = 0; i < c.size(); ++i)
      z[i] = Vec3{c[i], c[i], c[i]};
  } else {
    table.require_columns({"zd1_um", "zd2_um", "zd3_um"});
    const std::vector<double> c1 = table.column("zd1_um");
    const std::vector<double> c2 = table.column("zd2_um");
    const std::vector<double> c3 = table.column("zd3_um");
    for (std::size_t i = 0; i < c1.size(); ++i)
      z[i] = Vec3{c1[i], c2[i], c3[i]};
  }
  // Messages name the physical line, as CsvTable's do.
  for (std::size_t i = 0; i < t.size(); ++i) {
    const std::string where = fmt::format("{}:{}", path, table.line_of_row(i));
    if (t[i] < 0.0)
      throw core::InputError(fmt::format("{}: t_s = {} is negative", where, t[i]));
    if (i > 0 && !(t[i] > t[i - 1]))
      throw core::InputError(
          fmt::format("{}: t_s = {} does not increase (previous row: {})", where, t[i], t[i - 1]));
    for (double v : z[i]) {
      if (!(v >= 0.0 && v <= max_z_um))
        throw core::InputError(fmt::format(
            "{}: Z_d = {} um is outside [0, {}] um (the nominal stroke)", where, v, max_z_um));
    }
  }
  return from_samples(t, std::move(z), path, max_z_um);
}

Vec3 SetpointProfile::at(double t_s) noexcept {
  const std::size_t n = t_s_.size();
  if (t_s <= t_s_[0])
    return z_um_[0];
  if (t_s >= t_s_[n - 1])
    return z_um_[n - 1];
  if (cursor_ >= n - 1 || t_s < t_s_[cursor_])
    cursor_ = 0;  // time went back: search again from the start
  while (cursor_ + 1 < n && t_s_[cursor_ + 1] <= t_s)
    ++cursor_;
  const double t0 = t_s_[cursor_];
  const double t1 = t_s_[cursor_ + 1];
  const double a = (t_s - t0) / (t1 - t0);
  Vec3 z{};
  for (std::size_t i = 0; i < z.size(); ++i)
    z[i] = z_um_[cursor_][i] + a * (z_um_[cursor_ + 1][i] - z_um_[cursor_][i]);
  return z;
}

}  // namespace piezoshift::runtime
