#include "piezoshift/reproduction/measurement_report.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/io/csv_writer.hpp"
#include "piezoshift/io/plot.hpp"
#include "piezoshift/psi/png_image.hpp"
#include "piezoshift/psi/surface_figure.hpp"
#include "piezoshift/psi/zernike_figure.hpp"

namespace piezoshift::reproduction {
namespace {

namespace fs = std::filesystem;

std::string surface_caption(const PhaseMeasurement& m) {
  const auto [lo, hi] = psi::finite_range(m.analysis.surface_nm);
  return fmt::format(
      "Measured surface, piston and tilt removed: RMS {:.2f} nm, PV {:.2f} nm; colour scale {:.1f} "
      "to {:.1f} nm (blue to white to red); blank: no value",
      m.analysis.figures.rms, m.analysis.figures.pv, lo, hi);
}

// Per frame of the (single) average: commanded, recovered, true, their difference, settling.
std::vector<std::vector<std::string>> steps_table(const PhaseMeasurement& m) {
  std::vector<std::vector<std::string>> rows{
      {"frame", "commanded [rad]", "recovered from the fringes, AIA [rad]", "true [rad]",
       "recovered - true [mrad]", "settle [ms]", "true piston - commanded [nm]"}};
  const auto& rec = m.analysis.recovered_steps_rad.front();
  const auto& truth = m.analysis.true_steps_rad.front();
  for (std::size_t k = 0; k < m.params.steps_rad.size(); ++k) {
    const instrument::ExposureRecord& e = m.sequence.exposures[k];
    rows.push_back({fmt::format("{}", k), fmt::format("{:.4f}", m.params.steps_rad[k]),
                    fmt::format("{:.4f}", rec[k]), fmt::format("{:.4f}", truth[k]),
                    fmt::format("{:+.2f}", 1000.0 * (rec[k] - truth[k])),
                    fmt::format("{:.0f}", 1e3 * (e.settled_time_s - e.move_time_s)),
                    fmt::format("{:+.2f}", e.truth_piston_nm - e.commanded_piston_nm)});
  }
  return rows;
}

}  // namespace

void write_measurement_files(const PhaseMeasurement& m, const fs::path& dir, ReportFiles& files) {
  if (!m.validity.valid)
    return;
  const auto [lo, hi] = psi::finite_range(m.analysis.surface_nm);
  const io::Figure surface =
      psi::surface_figure(m.analysis.surface_nm, lo, hi,
                          fmt::format("Measured surface: RMS {:.2f} nm, PV {:.2f} nm",
                                      m.analysis.figures.rms, m.analysis.figures.pv));
  files.figures.push_back(*io::render(surface, dir / "measurement_surface_nm").png);
  files.captions.push_back(surface_caption(m));
  const io::Figure zernike = psi::zernike_figure(m.analysis.zernike_nm);
  files.figures.push_back(*io::render(zernike, dir / "measurement_zernike").png);
  files.captions.push_back(zernike.caption);
  io::CsvWriter w(
      (dir / "measurement_exposures.csv").string(),
      {"frame", "commanded_step_rad", "recovered_step_rad", "true_step_rad", "settle_s",
       "commanded_piston_nm", "truth_piston_nm", "truth_blur_nm", "gauge_error_mean_nm"},
      6);
  for (std::size_t k = 0; k < m.sequence.exposures.size(); ++k) {
    const instrument::ExposureRecord& e = m.sequence.exposures[k];
    w.row({static_cast<double>(k), e.commanded_step_rad, m.analysis.recovered_steps_rad[0][k],
           m.analysis.true_steps_rad[0][k], e.settled_time_s - e.move_time_s, e.commanded_piston_nm,
           e.truth_piston_nm, e.truth_blur_nm, e.gauge_error_mean_nm});
  }
  w.close();
  files.data.push_back(dir / "measurement_exposures.csv");
}

void measurement_section(Document& doc, const PhaseMeasurement& m) {
  doc.heading(2, "A phase-shifting measurement");
  const camera::CameraSettings& cs = m.camera.settings;
  doc.paragraph(fmt::format(
      "What the stage is for: {} frames of Hariharan's algorithm (steps of π/2 at {:g} nm, "
      "pistons of {:.1f} nm) taken from {:g} µm with the controller calibrated above, on a fresh "
      "twin session (seed {}) with the twin camera: a {} × {} px Fizeau looking at the default "
      "test surface, {:g} ms exposures, {:.1f} ms readout, the default [camera] (docs/camera.md). "
      "Each frame is exposed once the controller's own estimate has settled; the twin's truth is "
      "used only to score. The same code runs in `piezoshift measure` (docs/measure.md): "
      "`piezoshift measure --camera twin --free-run --seed {} --calibration calibration.toml "
      "--out DIR` in this folder takes this measurement again, number for number.",
      m.params.steps_rad.size(), m.params.wavelength_nm, m.params.wavelength_nm / 8.0,
      m.params.base_um, m.scene.seed, cs.width_px, cs.height_px, 1e3 * cs.exposure_s,
      1e3 * cs.readout_s, m.scene.seed));
  if (!m.validity.valid) {
    doc.code("NOT VALID: " + m.validity.reason);
    return;
  }
  const psi::SurfaceFigures& f = m.analysis.figures;
  const double added = std::sqrt(
      std::max(0.0, m.error_rms_nm * m.error_rms_nm - m.ideal_error_rms_nm * m.ideal_error_rms_nm));
  doc.table({{"measurement", "value"},
             {"surface RMS / PV / PVr",
              fmt::format("{:.2f} / {:.2f} / {:.2f} nm ({} pixels)", f.rms, f.pv, f.pvr, f.pixels)},
             {"measured - true surface, RMS", fmt::format("{:.3f} nm", m.error_rms_nm)},
             {"the same noise from an ideal stage (camera and algorithm floor)",
              fmt::format("{:.3f} nm", m.ideal_error_rms_nm)},
             {"what the stage added, √(error² − floor²)", fmt::format("{:.3f} nm", added)},
             {"steps: largest recovered - true, in magnitude",
              fmt::format("{:.2f} mrad", m.analysis.step_error_max_mrad)}});
  doc.table(steps_table(m));
  doc.paragraph(fmt::format(
      "Recovered: the steps the fringes show, by AIA started from the commanded ones; true: the "
      "twin plate's mean piston over each exposure. Settle: from the move until the controller's "
      "estimate (S - feedback, mean over {:g} ms) is within {:g} nm on every channel.",
      1e3 * m.params.on_target.hold_s, m.params.on_target.band_nm));
  doc.image(surface_caption(m), "measurement_surface_nm.png");
  doc.image("Zernike coefficients of the measured surface (Noll j ≥ 4), RMS-normalised in nm",
            "measurement_zernike.png");
}

}  // namespace piezoshift::reproduction
