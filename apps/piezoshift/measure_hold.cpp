#include "measure_hold.hpp"

#include <cmath>
#include <optional>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/instrument/hold_summary.hpp"
#include "piezoshift/io/csv_writer.hpp"
#include "piezoshift/io/plot.hpp"

namespace piezoshift::app {

std::string hold_markdown(const instrument::SequenceResult& s) {
  const instrument::HoldSummary h = instrument::hold_summary(s);
  return fmt::format(
      "| hold at frame 0: {} frames over {:.1f} s; the cavity's path from its set point (twin), "
      "RMS | {} |\n",
      h.frames, h.span_s,
      h.path_error_rms_nm ? fmt::format("{:.3f} nm", *h.path_error_rms_nm) : "(no truth)");
}

void write_hold(const instrument::SequenceResult& s, const std::filesystem::path& dir) {
  const instrument::HoldSummary h = instrument::hold_summary(s);
  const std::vector<double>& path = h.path_error_nm;
  const double nan = std::nan("");
  io::CsvWriter csv((dir / "hold.csv").string(),
                    {"trigger_time_s", "frame_id", "settle_s", "gauge_error_mean_nm",
                     "path_error_nm", "lock_correction_nm", "fringe_piston_nm"},
                    6, io::CsvWriter::Mode::kReplaceAtomically);
  std::vector<double> t, corr;
  for (std::size_t i = 0; i < s.hold.size(); ++i) {
    const instrument::ExposureRecord& e = s.hold[i];
    csv.row({e.trigger_time_s, static_cast<double>(e.frame_id), e.settled_time_s - e.move_time_s,
             e.gauge_error_mean_nm, path.empty() ? nan : path[i], e.lock_correction_nm,
             e.fringe_piston_nm});
    t.push_back(e.trigger_time_s);
    corr.push_back(e.lock_correction_nm);
  }
  csv.close();
  if (!io::find_gnuplot() || s.hold.empty())
    return;
  io::Figure f;
  f.width_px = 800;
  f.height_px = 520;
  io::Panel p;
  p.title = h.path_error_rms_nm ? fmt::format(
                                      "The hold: the cavity's path from its set point, "
                                      "RMS {:.3f} nm",
                                      *h.path_error_rms_nm)
                                : "The hold";
  p.x_label = "loop time [s]";
  p.y_label = "[nm]";
  if (!path.empty())
    p.series.push_back(io::line_series("cavity path - set point (twin truth)", t, path));
  if (std::isfinite(s.hold.front().lock_correction_nm))
    p.series.push_back(io::line_series("the lock's piston correction", t, corr));
  p.markers.push_back({.vertical = false, .at = 0.0, .label = ""});
  f.panels.push_back(p);
  io::render(f, dir / "hold");
}

}  // namespace piezoshift::app
