#include "piezoshift/reproduction/paper_bands.hpp"

#include <cmath>
#include <limits>

#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/reproduction/figure_format.hpp"

namespace piezoshift::reproduction {
namespace {

// band: the band as text; [lo, hi] its ends in unit.
PaperBandRow row(std::string figure, std::string paper, std::string band, double lo, double hi,
                 const std::string& unit, double value, const rig::Validity& v,
                 double resolution = 0.0) {
  PaperBandRow r;
  r.figure = std::move(figure);
  r.paper = std::move(paper);
  r.band = std::move(band);
  r.lo = lo;
  r.hi = hi;
  r.valid = v.valid;
  if (!v.valid) {
    r.twin = "NOT VALID: " + v.reason;
    return r;
  }
  r.twin = format_figure(value, unit, resolution);
  r.within = value >= lo && value <= hi;
  r.below = value < lo;
  return r;
}

}  // namespace

std::string PaperBandRow::verdict() const {
  if (!valid)
    return "not valid";
  if (within)
    return "within";
  return below ? "outside (below)" : "outside (above)";
}

std::vector<PaperBandRow> paper_band_rows(const ExperimentSet& e) {
  const double inf = std::numeric_limits<double>::infinity();
  return {
      row("open-loop travel (Section 4.1)", "12.9 µm", "12.9 ± 0.3 µm", 12.6, 13.2, "um",
          e.travel.open_loop_um, e.travel.validity),
      row("semi-closed-loop travel (Section 4.1)", "11.5 µm", "11.5 ± 0.5 µm", 11.0, 12.0, "um",
          e.travel.semi_closed_um, e.travel.validity,
          experiments::TravelRangeOptions{}.increment_um),
      row("Figure 10: 11 µm step, settled to ±2 %", "< 0.3 s", "< 0.3 s", -inf, 0.3, "s",
          e.step.metrics.settling_time_pct_s, e.step.validity),
      row("Figure 11: linearity (zero-end line)", "0.21 %", "0.1 to 0.4 %", 0.1, 0.4, "%",
          e.linearity.metrics.linearity_zero_end_pct, e.linearity.validity),
      row("Figure 12(a): repeatability at 5 µm (1 σ)", "2 nm", "1 to 3.5 nm", 1.0, 3.5, "nm",
          e.repeat_5um.metrics.repeatability_nm, e.repeat_5um.validity),
      row("Figure 12(b): repeatability at 10 µm (1 σ)", "3 nm", "1.5 to 4.5 nm", 1.5, 4.5, "nm",
          e.repeat_10um.metrics.repeatability_nm, e.repeat_10um.validity),
  };
}

}  // namespace piezoshift::reproduction
