#include "piezoshift/design/hinge_search.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include <fmt/core.h>

namespace piezoshift::design {

namespace {

// Grid count with a small tolerance so that e.g. 0.5 to 3.0 by 0.1 includes 3.0 despite rounding.
double raw_count(const SearchRange& r) {
  return std::floor((r.max_m - r.min_m) / r.step_m + 1e-9) + 1.0;
}

// Strict weak order for the ranking: the two scores (highest first), then the dimensions, so
// that ties never depend on the visiting order.
bool ranks_before(const HingeCandidate& a, const HingeCandidate& b, SearchRanking ranking) {
  const auto& ea = a.evaluation;
  const auto& eb = b.evaluation;
  const bool by_f = ranking == SearchRanking::natural_frequency;
  const double a1 = by_f ? ea.natural_frequency_Hz : ea.stress_margin;
  const double b1 = by_f ? eb.natural_frequency_Hz : eb.stress_margin;
  const double a2 = by_f ? ea.stress_margin : ea.natural_frequency_Hz;
  const double b2 = by_f ? eb.stress_margin : eb.natural_frequency_Hz;
  if (a1 != b1)
    return a1 > b1;
  if (a2 != b2)
    return a2 > b2;
  return std::tie(a.hinge.thickness_m, a.hinge.radius_m, a.hinge.width_m, a.hinge.link_length_m) <
         std::tie(b.hinge.thickness_m, b.hinge.radius_m, b.hinge.width_m, b.hinge.link_length_m);
}

}  // namespace

std::string search_range_problem(const SearchRange& r) {
  if (!(std::isfinite(r.min_m) && std::isfinite(r.max_m) && std::isfinite(r.step_m)))
    return "min, max and step must be finite numbers";
  if (!(r.min_m > 0.0))
    return fmt::format("min {} must be > 0", r.min_m);
  if (!(r.max_m >= r.min_m))
    return fmt::format("max {} must be >= min {}", r.max_m, r.min_m);
  if (!(r.step_m > 0.0))
    return fmt::format("step {} must be > 0", r.step_m);
  if (raw_count(r) > static_cast<double>(max_search_grid_points)) {
    return fmt::format("{} to {} by {} gives more than {} values", r.min_m, r.max_m, r.step_m,
                       max_search_grid_points);
  }
  return {};
}

std::size_t search_range_size(const SearchRange& r) {
  return static_cast<std::size_t>(raw_count(r));
}

std::vector<double> search_range_values(const SearchRange& r) {
  const std::size_t n = search_range_size(r);
  std::vector<double> values(n);
  for (std::size_t i = 0; i < n; ++i)
    values[i] = r.min_m + static_cast<double>(i) * r.step_m;
  return values;
}

HingeSearchResult search_hinge_designs(const DesignInputs& base, const HingeSearchSpace& space,
                                       const SearchConstraints& c, std::size_t max_candidates,
                                       SearchRanking ranking) {
  const std::pair<const char*, const SearchRange*> ranges[] = {{"thickness", &space.thickness},
                                                               {"radius", &space.radius},
                                                               {"width", &space.width},
                                                               {"link_length", &space.link_length}};
  double total = 1.0;
  for (const auto& [name, range] : ranges) {
    if (const std::string p = search_range_problem(*range); !p.empty())
      throw std::invalid_argument(fmt::format("search_hinge_designs: {} range: {}", name, p));
    total *= static_cast<double>(search_range_size(*range));
  }
  if (total > static_cast<double>(max_search_evaluations)) {
    throw std::invalid_argument(fmt::format("search_hinge_designs: {} grid points exceed {}", total,
                                            max_search_evaluations));
  }
  if (!(c.max_stiffness_ratio > 0.0 && c.min_stress_margin > 0.0 &&
        c.max_thickness_to_radius > 0.0 && std::isfinite(c.max_stiffness_ratio) &&
        std::isfinite(c.min_stress_margin) && std::isfinite(c.max_thickness_to_radius) &&
        std::isfinite(c.min_natural_frequency_Hz) && c.min_natural_frequency_Hz >= 0.0)) {
    throw std::invalid_argument(
        "search_hinge_designs: constraints must be positive and finite (frequency floor >= 0)");
  }
  // The base hinge is replaced on every grid point; check the rest of the inputs once.
  if (const std::string p = design_inputs_problem(base); !p.empty())
    throw std::invalid_argument("search_hinge_designs: base inputs: " + p);

  const std::vector<double> ts = search_range_values(space.thickness);
  const std::vector<double> rs = search_range_values(space.radius);
  const std::vector<double> bs = search_range_values(space.width);
  const std::vector<double> ls = search_range_values(space.link_length);

  HingeSearchResult result;
  std::vector<HingeCandidate> feasible;
  DesignInputs in = base;
  for (const double t : ts) {
    for (const double r : rs) {
      for (const double b : bs) {
        for (const double l : ls) {
          ++result.evaluated_count;
          in.hinge = HingeParams{b, t, r, l};
          if (!hinge_geometry_problem(in.hinge).empty() || t / r > c.max_thickness_to_radius) {
            ++result.geometry_rejected_count;
            continue;
          }
          const DesignEvaluation e = evaluate_design(in);
          if (e.stiffness_ratio <= c.max_stiffness_ratio &&
              e.stress_margin >= c.min_stress_margin && e.force_within_pushing_limit &&
              e.natural_frequency_Hz >= c.min_natural_frequency_Hz) {
            feasible.push_back({in.hinge, e});
          }
        }
      }
    }
  }
  result.feasible_count = feasible.size();
  const std::size_t keep = std::min(max_candidates, feasible.size());
  std::partial_sort(feasible.begin(), feasible.begin() + static_cast<std::ptrdiff_t>(keep),
                    feasible.end(), [ranking](const HingeCandidate& a, const HingeCandidate& b) {
                      return ranks_before(a, b, ranking);
                    });
  feasible.resize(keep);
  result.candidates = std::move(feasible);
  return result;
}

}  // namespace piezoshift::design
