#include "piezoshift/psi/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/psi/unwrap.hpp"
#include "piezoshift/psi/zernike.hpp"

namespace piezoshift::psi {

Mask modulated_pixels(const PhaseResult& phase, const Mask& mask, const AnalysisOptions& o) {
  const std::size_t need = static_cast<std::size_t>(std::max(o.zernike_terms, 36));
  const auto refuse = [need](std::size_t have) {
    return std::invalid_argument(fmt::format(
        "too few pixels with fringe modulation ({} of the {} needed): identical, blank or too "
        "small frames?",
        have, need));
  };
  std::vector<double> mod;
  for (std::size_t p = 0; p < mask.size(); ++p)
    if (mask.v[p] && std::isfinite(phase.modulation.v[p]))
      mod.push_back(phase.modulation.v[p]);
  if (mod.size() < need)
    throw refuse(mod.size());
  const auto mid = mod.begin() + static_cast<std::ptrdiff_t>(mod.size() / 2);
  std::nth_element(mod.begin(), mid, mod.end());
  const double floor = o.min_modulation_fraction * *mid;
  Mask valid(mask.width, mask.height, 0);
  for (std::size_t p = 0; p < mask.size(); ++p)
    valid.v[p] =
        mask.v[p] && std::isfinite(phase.phase_rad.v[p]) && phase.modulation.v[p] >= floor ? 1 : 0;
  if (valid.count() < need)
    throw refuse(valid.count());
  return valid;
}

Analysis analyze_frames(std::span<const Map> frames, const Mask& mask, const AnalysisOptions& o) {
  Analysis a;
  a.phase = wrapped_phase(frames, mask, o.phase);
  a.valid = modulated_pixels(a.phase, mask, o);
  Map phi = unwrap_phase(a.phase.phase_rad, a.valid);
  const double nm_per_rad = o.wavelength_nm / (4.0 * std::numbers::pi);
  for (double& v : phi.v)
    v *= nm_per_rad;
  a.surface_nm = remove_terms(phi, a.valid, o.removal);
  a.figures = surface_figures(a.surface_nm, a.valid);
  a.zernike_nm = fit_zernike(a.surface_nm, a.valid, o.zernike_terms);
  return a;
}

double surface_error_rms_nm(const Map& measured, const Map& truth, const Mask& mask) {
  Map diff(mask.width, mask.height, std::nan(""));
  Mask both(mask.width, mask.height, 0);
  for (std::size_t p = 0; p < mask.size(); ++p)
    if (mask.v[p] && std::isfinite(measured.v[p]) && std::isfinite(truth.v[p])) {
      diff.v[p] = measured.v[p] - truth.v[p];
      both.v[p] = 1;
    }
  return surface_figures(remove_terms(diff, both, Removal::kTilt), both, false).rms;
}

}  // namespace piezoshift::psi
