#include "measure_report.hpp"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <vector>

#include <fmt/core.h>

#include "measure_hold.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/csv_writer.hpp"
#include "piezoshift/io/plot.hpp"
#include "piezoshift/procedures/measure_json.hpp"
#include "piezoshift/psi/npy.hpp"
#include "piezoshift/psi/png_image.hpp"
#include "piezoshift/psi/surface_datx.hpp"
#include "piezoshift/psi/surface_figure.hpp"
#include "piezoshift/psi/surface_file.hpp"
#include "piezoshift/psi/zernike_figure.hpp"

namespace piezoshift::app {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

io::Panel panel(std::string title, std::string x_label, std::string y_label) {
  io::Panel p;
  p.title = std::move(title);
  p.x_label = std::move(x_label);
  p.y_label = std::move(y_label);
  return p;
}

void write_exposures_csv(const instrument::SequenceResult& s, const fs::path& path) {
  io::CsvWriter csv(
      path.string(),
      {"average", "frame", "frame_id", "commanded_step_rad", "commanded_piston_nm", "move_time_s",
       "settle_s", "trigger_time_s", "exposure_end_s", "gauge_error_mean_nm", "gauge_error_max_nm",
       "truth_piston_nm", "truth_blur_nm", "truth_tip_urad", "truth_tilt_urad", "arrival_wall_s"},
      6, io::CsvWriter::Mode::kReplaceAtomically);
  for (const instrument::ExposureRecord& e : s.exposures) {
    const double nan = std::nan("");
    csv.row({static_cast<double>(e.average + 1), static_cast<double>(e.frame),
             static_cast<double>(e.frame_id), e.commanded_step_rad, e.commanded_piston_nm,
             e.move_time_s, e.settled_time_s - e.move_time_s, e.trigger_time_s, e.exposure_end_s,
             e.gauge_error_mean_nm, e.gauge_error_max_nm, e.has_truth ? e.truth_piston_nm : nan,
             e.has_truth ? e.truth_blur_nm : nan, e.has_truth ? e.truth_tip_urad : nan,
             e.has_truth ? e.truth_tilt_urad : nan, e.arrival_wall_s});
  }
  csv.close();
}

// Frames as 16-bit PNG holding the camera's own counts (0 .. 2^bits - 1), so that `psi analyze`
// and `--camera files:DIR` with the same pixel format read them back as they were taken.
void write_frames(const MeasureRecord& r, const fs::path& dir) {
  fs::create_directories(dir);
  const std::size_t n = r.params->steps_rad.size();
  for (std::size_t i = 0; i < r.sequence->frames.size(); ++i) {
    const camera::Frame& f = r.sequence->frames[i];
    psi::Map m(f.width_px, f.height_px);
    std::copy(f.counts.begin(), f.counts.end(), m.v.begin());
    psi::write_png_gray16((dir / fmt::format("frame_a{}_{:02}.png", i / n + 1, i % n)).string(), m);
  }
}

io::Figure zernike_figure(const instrument::MeasurementAnalysis& a) {
  return psi::zernike_figure(a.zernike_nm);
}

// The steps as commanded, as recovered from the fringes (AIA) and, on the twin, as made; below,
// recovered minus true (or minus commanded without truth) in mrad. Without recovered steps (AIA
// did not converge) the title says why and the lower panel shows true - commanded.
io::Figure steps_figure(const MeasureRecord& r) {
  const instrument::MeasurementAnalysis& a = *r.analysis;
  const std::vector<double>& commanded = r.params->steps_rad;
  const std::vector<double>& rec = a.recovered_steps_rad.front();
  const bool truth = !a.true_steps_rad.empty();
  const std::vector<double>& lhs =
      rec.empty() ? (truth ? a.true_steps_rad.front() : commanded) : rec;
  const std::vector<double>& rhs = rec.empty() || !truth ? commanded : a.true_steps_rad.front();
  io::Figure f;
  f.rows = 2;
  f.width_px = 800;
  f.height_px = 760;
  io::Panel top =
      panel(rec.empty() ? "Phase steps, average 1 (not recovered: " + a.steps_reason + ")"
                        : "Phase steps, average 1",
            "frame number", "step [rad]");
  io::Panel bottom =
      panel(rec.empty() ? (truth ? "true - commanded" : "(no recovered steps)")
                        : (truth ? "recovered from the fringes - true" : "recovered - commanded"),
            "frame number", "difference [mrad]");
  std::vector<double> k, diff;
  for (std::size_t i = 0; i < commanded.size(); ++i) {
    k.push_back(static_cast<double>(i));
    diff.push_back(1000.0 * (lhs[i] - rhs[i]));
  }
  // Frames are whole numbers: a margin of a third of a frame keeps the first and last off the
  // frame of the plot.
  top.x_range = bottom.x_range = std::pair{-0.35, static_cast<double>(commanded.size()) - 0.65};
  top.series.push_back(io::line_series("commanded", k, commanded));
  if (!rec.empty())
    top.series.push_back(io::point_series("recovered (AIA)", k, rec));
  if (truth)
    top.series.push_back(io::point_series("true (twin)", k, a.true_steps_rad.front()));
  bottom.series.push_back(io::point_series("", k, diff));
  bottom.markers.push_back({.vertical = false, .at = 0.0, .label = ""});
  bottom.key = "off";
  f.panels = {top, bottom};
  return f;
}

// Where the stage was while each frame was exposed, against the commanded piston.
io::Figure stage_figure(const MeasureRecord& r) {
  io::Figure f;
  f.width_px = 800;
  f.height_px = 520;
  io::Panel p = panel("The stage during each exposure", "exposure number", "error [nm]");
  std::vector<double> k, gauge, truth;
  for (std::size_t i = 0; i < r.sequence->exposures.size(); ++i) {
    const instrument::ExposureRecord& e = r.sequence->exposures[i];
    k.push_back(static_cast<double>(i));
    gauge.push_back(e.gauge_error_mean_nm);
    if (e.has_truth)
      truth.push_back(e.truth_piston_nm - e.commanded_piston_nm);
  }
  p.series.push_back(io::point_series("gauges: mean |S - feedback|, worst channel", k, gauge));
  if (truth.size() == k.size())
    p.series.push_back(io::point_series("true piston - commanded (twin)", k, truth));
  p.markers.push_back({.vertical = false, .at = 0.0, .label = ""});
  f.panels.push_back(p);
  return f;
}

std::string report_markdown(const MeasureRecord& r) {
  const instrument::MeasurementAnalysis& a = *r.analysis;
  const instrument::SequenceResult& s = *r.sequence;
  const procedures::MeasureOutcome& m = *r.outcome;
  std::string md = fmt::format(
      "# Phase-shifting measurement\n\n"
      "Camera `{}`, DAQ `{}` at {} Hz ({} clock), algorithm `{}`, {} frames x {} averages; "
      "calibration: {}.\n\n"
      "| figure | value |\n|---|---|\n"
      "| surface RMS | {:.3f} nm |\n| surface PV | {:.3f} nm |\n| surface PVr | {:.3f} nm |\n"
      "| valid pixels | {} |\n| steps: worst recovered - true | {} |\n"
      "| measurement, wall time | {:.3f} s (floor {:.3f} s, ratio {:.2f}) |\n"
      "| loop overruns | {} |\n",
      m.camera, m.daq, m.rate_Hz, m.real_time ? "real-time" : "simulated", m.algorithm,
      r.params->steps_rad.size(), r.params->averages, m.calibration_source, a.figures.rms,
      a.figures.pv, a.figures.pvr, a.figures.pixels, a.step_error_text(), s.wall_time_s, s.floor_s,
      s.floor_s > 0 ? s.wall_time_s / s.floor_s : 0.0, s.overruns);
  if (m.error_rms_nm)
    md += fmt::format("| measured - true surface, RMS | {:.3f} nm |\n", *m.error_rms_nm);
  if (m.ideal_error_rms_nm)
    md += fmt::format(
        "| the same frames from an ideal stage (camera and algorithm floor, one average) | "
        "{:.3f} nm |\n",
        *m.ideal_error_rms_nm);
  if (m.floor_error_rms_nm && m.error_rms_nm)
    md += fmt::format(
        "| the whole measurement from an ideal stage (its floor) / what the stage added, "
        "sqrt(measured^2 - floor^2) | {:.3f} / {:.3f} nm |\n",
        *m.floor_error_rms_nm,
        procedures::stage_error_rms_nm(*m.error_rms_nm, *m.floor_error_rms_nm));
  if (const std::optional<double> path =
          instrument::path_error_rms_nm(s, r.params->steps_rad.size()))
    md += fmt::format(
        "| the cavity's path from its set point after the first average (twin), RMS | {:.3f} nm "
        "|\n",
        *path);
  if (s.lock)
    md += fmt::format(
        "| fringe lock | {} frames locked, {} without a pose ({} lost, {} taken again){}; "
        "correction at the end {:.3f} nm, {:.4f} / {:.4f} urad |\n",
        s.lock->locked, s.lock->holding, s.lock->lost, s.lock->retaken,
        s.lock->first_refusal.empty() ? std::string() : "; first: " + s.lock->first_refusal,
        s.lock->correction[0], s.lock->correction[1], s.lock->correction[2]);
  if (!s.hold.empty())
    md += hold_markdown(s);
  md +=
      "\n![surface](surface_nm.png)\n\n![Zernike](zernike.png)\n\n![steps](steps.png)\n\n"
      "![stage](stage.png)\n";
  if (!s.hold.empty())
    md += "\n![hold](hold.png)\n";
  return md;
}

}  // namespace

MeasureRecord measure_record(const procedures::MeasureOutcome& m) {
  return MeasureRecord{.outcome = &m,
                       .params = &m.params,
                       .sequence = &m.sequence,
                       .analysis = &*m.analysis,
                       .mask = &m.mask,
                       .truth_nm = m.truth_nm ? &*m.truth_nm : nullptr,
                       .out = {},
                       .out_given = {},
                       .m_per_px = m.m_per_px};
}

Json measure_json(const MeasureRecord& r) {
  return procedures::measure_json(*r.outcome, {.out = r.out, .out_given = r.out_given});
}

std::optional<fs::path> measurement_destination(const fs::path& out) {
  const auto is_free = [](const fs::path& p) {
    std::error_code ec;
    const fs::file_status st = fs::symlink_status(p, ec);
    if (st.type() == fs::file_type::not_found)
      return true;
    return fs::is_directory(st) && fs::is_empty(p, ec) && !ec;
  };
  if (is_free(out))
    return out;
  // "DIR/" names DIR: its siblings are DIR.1, ... (not DIR/.1)
  fs::path base = out;
  while (!base.has_filename() && base.has_relative_path())
    base = base.parent_path();
  for (int k = 1; k < 100; ++k) {
    const fs::path p = base.string() + fmt::format(".{}", k);
    std::error_code ec;
    if (fs::symlink_status(p, ec).type() == fs::file_type::not_found)
      return p;
  }
  return std::nullopt;
}

namespace {

// The built folder renamed to where the measurement now goes (an empty folder there gives way);
// false when out and out.1 .. out.99 are all taken. r.out / r.out_given say where it went, and
// measurement.json is written again when that is not --out.
bool move_into_place(MeasureRecord& r, const fs::path& built, const std::string& out_name) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::optional<fs::path> dest = measurement_destination(out_name);
    if (!dest)
      return false;
    if (*dest != fs::path(out_name) && r.out_given.empty()) {
      r.out_given = out_name;
      fmt::print(stderr,
                 "piezoshift: measure: --out {}: something appeared in it while the measurement "
                 "ran; the measurement is written to {} instead\n",
                 out_name, dest->string());
    }
    if (r.out != dest->string()) {
      r.out = dest->string();
      io::write_file_atomically((built / "measurement.json").string(),
                                measure_json(r).dump(2) + "\n");
    }
    std::error_code ec;
    if (fs::is_directory(fs::symlink_status(*dest, ec)))
      fs::remove(*dest, ec);  // only an empty folder is removed
    fs::rename(built, *dest, ec);
    if (!ec)
      return true;
    // Taken between the look and the rename: look again.
  }
  return false;
}

}  // namespace

void write_measurement(MeasureRecord& r, const std::string& out_name) {
  const fs::path out(out_name);
  const fs::path tmp = out.string() + fmt::format(".partial-{}", ::getpid());
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  r.out = out_name;
  try {
    write_frames(r, tmp / "frames");
    psi::write_mask_png((tmp / "mask.png").string(), *r.mask);
    psi::write_npy((tmp / "surface_nm.npy").string(), r.analysis->surface_nm);
    if (r.m_per_px > 0.0) {
      const psi::ScaledSurface s{r.analysis->surface_nm, r.m_per_px,
                                 "surface, piston and tilt removed"};
      psi::write_gsf((tmp / "surface_m.gsf").string(), s);
      psi::write_datx((tmp / "surface_nm.datx").string(), s, r.params->wavelength_nm * 1e-9);
    }
    const auto [lo, hi] = psi::finite_range(r.analysis->surface_nm);
    psi::write_surface_map(tmp / "surface_nm.png", r.analysis->surface_nm, lo, hi,
                           fmt::format("Measured surface: RMS {:.2f} nm, PV {:.2f} nm",
                                       r.analysis->figures.rms, r.analysis->figures.pv));
    if (r.truth_nm != nullptr)
      psi::write_npy((tmp / "surface_truth_nm.npy").string(), *r.truth_nm);
    write_exposures_csv(*r.sequence, tmp / "exposures.csv");
    if (!r.sequence->hold.empty())
      write_hold(*r.sequence, tmp);
    io::write_file_atomically((tmp / "measurement.json").string(), measure_json(r).dump(2) + "\n");
    if (io::find_gnuplot()) {
      io::render(zernike_figure(*r.analysis), tmp / "zernike");
      io::render(steps_figure(r), tmp / "steps");
      io::render(stage_figure(r), tmp / "stage");
    }
    io::write_file_atomically((tmp / "report.md").string(), report_markdown(r));
  } catch (...) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    throw;
  }
  // The finished measurement is kept whatever --out has become.
  if (!move_into_place(r, tmp, out_name))
    throw core::InputError(
        fmt::format("--out {}: it and {}.1 .. {}.99 are all taken; the measurement is kept in {}",
                    out_name, out_name, out_name, tmp.string()));
}

}  // namespace piezoshift::app
