#include "piezoshift/instrument/measurement.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

#include <fmt/core.h>

#include "piezoshift/psi/zernike.hpp"

namespace piezoshift::instrument {

std::vector<psi::Map> frame_maps(const std::vector<camera::Frame>& frames) {
  std::vector<psi::Map> maps;
  maps.reserve(frames.size());
  for (const camera::Frame& f : frames) {
    psi::Map m(f.width_px, f.height_px);
    std::transform(f.counts.begin(), f.counts.end(), m.v.begin(),
                   [](std::uint16_t c) { return static_cast<double>(c); });
    maps.push_back(std::move(m));
  }
  return maps;
}

bool MeasurementAnalysis::has_step_error() const {
  return !true_steps_rad.empty() &&
         std::any_of(recovered_steps_rad.begin(), recovered_steps_rad.end(),
                     [](const std::vector<double>& s) { return !s.empty(); });
}

std::string MeasurementAnalysis::step_error_text() const {
  if (true_steps_rad.empty())
    return "(no truth)";
  if (!has_step_error())
    return "(not recovered: " + steps_reason + ")";
  return fmt::format("{:.2f} mrad", step_error_max_mrad);
}

namespace {

// The steps the frames show, by AIA started from the commanded ones.
psi::PhaseResult recover_steps(std::span<const psi::Map> frames, const psi::Mask& mask,
                               const std::vector<double>& commanded) {
  psi::PhaseOptions o;
  o.algorithm = psi::Algorithm::kAia;
  o.steps_rad = commanded;
  return psi::wrapped_phase(frames, mask, o);
}

std::vector<double> true_steps(std::span<const ExposureRecord> exposures, double wavelength_nm) {
  std::vector<double> steps;
  for (const ExposureRecord& e : exposures)
    steps.push_back(4.0 * std::numbers::pi * (e.truth_piston_nm - exposures[0].truth_piston_nm) /
                    wavelength_nm);
  return steps;
}

void average_into(MeasurementAnalysis& m, const std::vector<psi::Analysis>& analyses) {
  const psi::Map& first = analyses.front().surface_nm;
  m.surface_nm = psi::Map(first.width, first.height, std::nan(""));
  m.valid = psi::Mask(first.width, first.height, 0);
  for (std::size_t p = 0; p < first.size(); ++p) {
    double sum = 0.0;
    bool all = true;
    for (const psi::Analysis& a : analyses) {
      all = all && a.valid.v[p] && std::isfinite(a.surface_nm.v[p]);
      sum += a.surface_nm.v[p];
    }
    if (all) {
      m.surface_nm.v[p] = sum / static_cast<double>(analyses.size());
      m.valid.v[p] = 1;
    }
  }
}

}  // namespace

MeasurementAnalysis analyze_measurement(const SequenceResult& sequence,
                                        const SequenceParams& params, const psi::Mask& mask,
                                        const psi::AnalysisOptions& options) {
  MeasurementAnalysis m;
  const std::vector<psi::Map> maps = frame_maps(sequence.frames);
  const std::size_t n = params.steps_rad.size();
  std::vector<psi::Analysis> analyses;
  for (int a = 0; a < params.averages; ++a) {
    const std::span<const psi::Map> frames(maps.data() + static_cast<std::size_t>(a) * n, n);
    const std::span<const ExposureRecord> exposures(
        sequence.exposures.data() + static_cast<std::size_t>(a) * n, n);
    analyses.push_back(psi::analyze_frames(frames, mask, options));
    const psi::PhaseResult& fit = analyses.back().phase;
    if (!fit.converged && m.converged) {
      m.converged = false;
      m.reason = fmt::format("average {}: {}", a + 1,
                             fit.reason.empty() ? "the fit did not converge" : fit.reason);
    }
    m.average_figures.push_back(analyses.back().figures);
    if (!exposures.empty() && exposures[0].has_truth)
      m.true_steps_rad.push_back(true_steps(exposures, params.wavelength_nm));
    const psi::PhaseResult steps = recover_steps(frames, mask, params.steps_rad);
    if (!steps.converged) {
      if (m.steps_reason.empty())
        m.steps_reason = fmt::format("average {}: {}", a + 1, steps.reason);
      m.recovered_steps_rad.emplace_back();
      continue;
    }
    m.recovered_steps_rad.push_back(steps.steps_rad);
    for (std::size_t k = 0; !m.true_steps_rad.empty() && k < n; ++k)
      m.step_error_max_mrad =
          std::max(m.step_error_max_mrad,
                   1000.0 * std::fabs(steps.steps_rad[k] - m.true_steps_rad.back()[k]));
  }
  average_into(m, analyses);
  m.figures = psi::surface_figures(m.surface_nm, m.valid);
  m.zernike_nm = psi::fit_zernike(m.surface_nm, m.valid, options.zernike_terms);
  return m;
}

}  // namespace piezoshift::instrument
