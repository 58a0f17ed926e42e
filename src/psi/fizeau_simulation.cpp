#include "piezoshift/psi/fizeau_simulation.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/psi/zernike.hpp"

namespace piezoshift::psi {

SurfaceSpec parse_surface_spec(std::string_view spec) {
  SurfaceSpec s;
  s.zernike_nm.clear();
  s.roughness_rms_nm = 0.0;
  if (spec == "flat")
    return s;
  auto fail = [&](std::string_view item, std::string_view why) {
    return core::InputError(fmt::format(
        "--surface '{}': '{}' {} (expected e.g. Z4=40,Z5=-20,rough=0.5)", spec, item, why));
  };
  std::size_t at = 0;
  while (at <= spec.size()) {
    const std::size_t end = std::min(spec.find(',', at), spec.size());
    const std::string_view item = spec.substr(at, end - at);
    at = end + 1;
    if (item.empty())
      throw fail(item, "is empty");
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos)
      throw fail(item, "has no '='");
    const std::string_view key = item.substr(0, eq), val = item.substr(eq + 1);
    double v = 0.0;
    const auto [p, ec] = std::from_chars(val.data(), val.data() + val.size(), v);
    if (ec != std::errc{} || p != val.data() + val.size() || !std::isfinite(v))
      throw fail(item, "has no number after '='");
    if (key == "rough") {
      if (v < 0.0 || v > kMaxRoughnessRmsNm)
        throw fail(item, fmt::format("must be in 0..{} nm RMS (docs/psi.md)", kMaxRoughnessRmsNm));
      s.roughness_rms_nm = v;
      continue;
    }
    int j = 0;
    if (key.size() < 2 || (key[0] != 'Z' && key[0] != 'z'))
      throw fail(item, "is neither Z<j> nor rough");
    const auto [q, ec2] = std::from_chars(key.data() + 1, key.data() + key.size(), j);
    if (ec2 != std::errc{} || q != key.data() + key.size() || j < 1 || j > 231)
      throw fail(item, "needs a Noll index 1..231");
    if (std::abs(v) > kMaxSurfaceTermNm)
      throw fail(item,
                 fmt::format("is beyond +-{} nm RMS per term (docs/psi.md)", kMaxSurfaceTermNm));
    s.zernike_nm.emplace_back(j, v);
  }
  // Noll terms are orthonormal: the surface's RMS is the root sum of squares of the summed
  // coefficients of each index.
  std::vector<double> sum(232, 0.0);
  for (const auto& [j, c] : s.zernike_nm)
    sum[static_cast<std::size_t>(j)] += c;
  double squares = 0.0;
  for (double c : sum)
    squares += c * c;
  if (std::sqrt(squares) > kMaxSurfaceTermNm)
    throw core::InputError(
        fmt::format("--surface '{}': the terms make {:.0f} nm RMS, beyond {} nm RMS (docs/psi.md)",
                    spec, std::sqrt(squares), kMaxSurfaceTermNm));
  return s;
}

Map make_surface_nm(const SurfaceSpec& spec, const Mask& mask, plant::Rng& rng) {
  int terms = 0;
  for (const auto& [j, c] : spec.zernike_nm)
    terms = std::max(terms, j);
  std::vector<double> coef(static_cast<std::size_t>(terms), 0.0);
  for (const auto& [j, c] : spec.zernike_nm)
    coef[static_cast<std::size_t>(j - 1)] += c;
  Map s = terms > 0 ? zernike_surface(coef, mask) : Map(mask.width, mask.height, 0.0);
  for (std::size_t p = 0; p < s.size(); ++p)
    if (!mask.v[p])
      s.v[p] = std::nan("");
  if (spec.roughness_rms_nm > 0.0) {
    Map noise(mask.width, mask.height);
    for (double& v : noise.v)
      v = rng.normal();
    // box filter (separable) for a correlation length, then scale to the RMS over the pupil
    const int r = std::max(0, spec.roughness_correlation_px / 2);
    Map tmp = noise;
    for (int j = 0; j < mask.height; ++j)
      for (int i = 0; i < mask.width; ++i) {
        double acc = 0.0;
        for (int d = -r; d <= r; ++d)
          acc += noise.at(std::clamp(i + d, 0, mask.width - 1), j);
        tmp.at(i, j) = acc;
      }
    for (int j = 0; j < mask.height; ++j)
      for (int i = 0; i < mask.width; ++i) {
        double acc = 0.0;
        for (int d = -r; d <= r; ++d)
          acc += tmp.at(i, std::clamp(j + d, 0, mask.height - 1));
        noise.at(i, j) = acc;
      }
    double sum = 0.0, sum2 = 0.0;
    std::size_t n = 0;
    for (std::size_t p = 0; p < s.size(); ++p)
      if (mask.v[p]) {
        sum += noise.v[p];
        sum2 += noise.v[p] * noise.v[p];
        ++n;
      }
    const double mean = n ? sum / static_cast<double>(n) : 0.0;
    const double rms =
        n ? std::sqrt(std::max(1e-300, sum2 / static_cast<double>(n) - mean * mean)) : 1.0;
    for (std::size_t p = 0; p < s.size(); ++p)
      if (mask.v[p])
        s.v[p] += spec.roughness_rms_nm * (noise.v[p] - mean) / rms;
  }
  return s;
}

std::string fizeau_problem(const FizeauParams& f) {
  if (f.width_px < 8 || f.height_px < 8 || f.width_px > 2048 || f.height_px > 2048)
    return fmt::format("camera size {} x {}: each side 8..2048 px", f.width_px, f.height_px);
  if (!(f.pupil_radius_px >= 2.0))
    return fmt::format("pupil_radius_px = {}: must be >= 2", f.pupil_radius_px);
  if (!(f.pupil_radius_m > 0.0 && f.pupil_radius_m < 1.0))
    return fmt::format("pupil_radius_m = {}: must be in (0, 1)", f.pupil_radius_m);
  if (!(f.wavelength_nm >= 100.0 && f.wavelength_nm <= 20000.0))
    return fmt::format("wavelength_nm = {}: must be in 100..20000", f.wavelength_nm);
  if (f.subsamples < 1 || f.subsamples > 64)
    return fmt::format("subsamples = {}: must be in 1..64", f.subsamples);
  return {};
}

std::string camera_problem(const CameraParams& c) {
  if (!(c.exposure_s > 0.0 && c.exposure_s <= 1.0))
    return fmt::format("exposure_s = {}: must be in (0, 1]", c.exposure_s);
  if (!(c.full_well_e >= 100.0))
    return fmt::format("full_well_e = {}: must be >= 100", c.full_well_e);
  if (!(c.mean_fill > 0.0 && c.mean_fill < 1.0))
    return fmt::format("mean_fill = {}: must be in (0, 1)", c.mean_fill);
  if (!(c.visibility > 0.0 && c.visibility <= 1.0))
    return fmt::format("visibility = {}: must be in (0, 1]", c.visibility);
  if (!(c.read_noise_e >= 0.0))
    return fmt::format("read_noise_e = {}: must be >= 0", c.read_noise_e);
  if (c.bit_depth < 8 || c.bit_depth > 16)
    return fmt::format("bit_depth = {}: must be in 8..16", c.bit_depth);
  return {};
}

Map render_frame(const Map& surface_nm, const Mask& mask, const FizeauParams& f,
                 const CameraParams& cam, std::span<const PoseSample> exposure, plant::Rng& rng) {
  if (exposure.empty())
    throw std::invalid_argument("render_frame: no pose sample");
  // the pose at the integration points: midpoints of subsamples per interval
  std::vector<PoseSample> pts;
  if (exposure.size() == 1) {
    pts.push_back(exposure[0]);
  } else {
    for (std::size_t k = 0; k + 1 < exposure.size(); ++k)
      for (int s = 0; s < f.subsamples; ++s) {
        const double u = (s + 0.5) / f.subsamples;
        const PoseSample& a = exposure[k];
        const PoseSample& b = exposure[k + 1];
        pts.push_back({a.time_s + u * (b.time_s - a.time_s),
                       a.piston_nm + u * (b.piston_nm - a.piston_nm),
                       a.theta_x_urad + u * (b.theta_x_urad - a.theta_x_urad),
                       a.theta_y_urad + u * (b.theta_y_urad - a.theta_y_urad)});
      }
  }
  const double k_rad_per_nm = 4.0 * std::numbers::pi / f.wavelength_nm;
  const double cx = 0.5 * (f.width_px - 1), cy = 0.5 * (f.height_px - 1);
  const double m_per_px = f.pupil_radius_m / f.pupil_radius_px;
  const double mean_e = cam.full_well_e * cam.mean_fill;
  const double levels = std::ldexp(1.0, cam.bit_depth) - 1.0;
  const double inv_n = 1.0 / static_cast<double>(pts.size());
  Map out(f.width_px, f.height_px);
  for (int j = 0; j < f.height_px; ++j) {
    const double y_m = (cy - j) * m_per_px;
    for (int i = 0; i < f.width_px; ++i) {
      const std::size_t p = static_cast<std::size_t>(j) * f.width_px + i;
      double fringe = 0.0;
      if (mask.v[p] && std::isfinite(surface_nm.v[p])) {
        const double x_m = (i - cx) * m_per_px;
        const double base = k_rad_per_nm * surface_nm.v[p];
        double acc = 0.0;
        for (const PoseSample& s : pts) {
          // urad * m = um; 1000 nm per um
          const double dz_nm = s.piston_nm + 1000.0 * (s.theta_x_urad * y_m - s.theta_y_urad * x_m);
          acc += std::cos(base + k_rad_per_nm * dz_nm);
        }
        fringe = acc * inv_n;
      }
      double e = mean_e * (1.0 + cam.visibility * fringe);
      if (cam.shot_noise)
        e += std::sqrt(std::max(e, 0.0)) * rng.normal();
      e += cam.read_noise_e * rng.normal();
      e = std::clamp(e, 0.0, cam.full_well_e);
      out.v[p] = std::round(e / cam.full_well_e * levels);
    }
  }
  return out;
}

}  // namespace piezoshift::psi
