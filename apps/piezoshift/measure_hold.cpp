#include "measure_hold.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/io/csv_writer.hpp"
#include "piezoshift/io/plot.hpp"

namespace piezoshift::app {

namespace {

using Json = nlohmann::json;

// The RMS of the path's means over whole seconds of the hold: the drift a lock at the frame rate
// is there to hold, without the inner loop's jitter from exposure to exposure, which averages out.
std::optional<double> second_means_rms_nm(const instrument::SequenceResult& s,
                                          const std::vector<double>& path) {
  if (path.empty())
    return std::nullopt;
  const double t0 = s.hold.front().trigger_time_s;
  std::vector<double> sum, count;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const auto k = static_cast<std::size_t>(s.hold[i].trigger_time_s - t0);
    if (k >= sum.size()) {
      sum.resize(k + 1, 0.0);
      count.resize(k + 1, 0.0);
    }
    sum[k] += path[i];
    count[k] += 1.0;
  }
  double sq = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k + 1 < sum.size(); ++k)  // the last second is not whole
    if (count[k] > 0.0) {
      sq += (sum[k] / count[k]) * (sum[k] / count[k]);
      ++n;
    }
  if (n == 0)
    return std::nullopt;
  return std::sqrt(sq / static_cast<double>(n));
}

double hold_span_s(const instrument::SequenceResult& s) {
  return s.hold.size() < 2 ? 0.0 : s.hold.back().trigger_time_s - s.hold.front().trigger_time_s;
}

}  // namespace

Json hold_json(const instrument::SequenceResult& s) {
  const std::vector<double> path = instrument::path_errors_nm(s, s.hold);
  const std::optional<double> rms = instrument::hold_path_error_rms_nm(s);
  double worst = 0.0;
  for (double d : path)
    worst = std::max(worst, std::fabs(d));
  std::map<std::string, std::size_t> states;
  for (const instrument::ExposureRecord& e : s.hold)
    if (!e.lock_state.empty())
      ++states[e.lock_state];
  const double span = hold_span_s(s);
  const std::optional<double> slow = second_means_rms_nm(s, path);
  return {{"frames", s.hold.size()},
          {"span_s", span},
          {"frame_interval_s",
           s.hold.size() < 2 ? Json(nullptr) : Json(span / static_cast<double>(s.hold.size() - 1))},
          {"path_error_rms_nm", rms ? Json(*rms) : Json(nullptr)},
          {"path_error_max_nm", path.empty() ? Json(nullptr) : Json(worst)},
          {"path_error_1s_means_rms_nm", slow ? Json(*slow) : Json(nullptr)},
          {"lock_states", states.empty() ? Json(nullptr) : Json(states)}};
}

std::string hold_markdown(const instrument::SequenceResult& s) {
  const std::optional<double> rms = instrument::hold_path_error_rms_nm(s);
  return fmt::format(
      "| hold at frame 0: {} frames over {:.1f} s; the cavity's path from its set point (twin), "
      "RMS | {} |\n",
      s.hold.size(), hold_span_s(s), rms ? fmt::format("{:.3f} nm", *rms) : "(no truth)");
}

void write_hold(const instrument::SequenceResult& s, const std::filesystem::path& dir) {
  const std::vector<double> path = instrument::path_errors_nm(s, s.hold);
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
  const std::optional<double> rms = instrument::hold_path_error_rms_nm(s);
  io::Panel p;
  p.title = rms ? fmt::format("The hold: the cavity's path from its set point, RMS {:.3f} nm", *rms)
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
