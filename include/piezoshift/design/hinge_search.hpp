#pragma once
// A grid search over the hinge dimensions (t, R, b, L) for designs that keep the mechanism soft
// enough for the actuator and the hinges strong enough for the full stroke (not in the paper,
// which gives one design, Table 3):
//
//   for every (t, R, b, L) on the grid:
//     reject unless  t < 2R,  L > 2R,  t/R <= max_thickness_to_radius     (geometry)
//     evaluate_design(inputs with that hinge)
//     feasible when  k_m / k_a <= max_stiffness_ratio                    (default 0.1, Sec. 2.2)
//               and  allowable / sigma_max(x_m) >= min_stress_margin     (default 2)
//               and  k_m x_m <= the actuator's pushing force
//               and  f >= min_natural_frequency_Hz                          (default 0: no limit)
//   rank the feasible, best first, by
//     SearchRanking::natural_frequency: f, then stress margin (the stiffest feasible mechanism)
//     SearchRanking::stress_margin:     stress margin, then f (the most robust one)
//   then by (t, R, b, L); keep the first max_candidates.
//
// Ranked by frequency, the best candidates all sit just under the stiffness limit and differ by
// a fraction of a hertz; their stress margins then tell them apart. Ranking by margin with a
// frequency floor asks the other question: the strongest hinge that is still fast enough.
//
// The actuator, material and moving mass stay those of the inputs. The mass is held fixed
// although it would change a little with the hinge dimensions: it is mostly the moving platform.
#include <cstddef>
#include <string>
#include <vector>

#include "piezoshift/design/design_evaluation.hpp"
#include "piezoshift/design/design_inputs.hpp"

namespace piezoshift::design {

//! Grid values min, min + step, ... up to max (inclusive within 1e-9 step) [m].
struct SearchRange {
  double min_m = 0.0;
  double max_m = 0.0;
  double step_m = 0.0;
};

//! Why a range cannot be searched ("" when it can): min > 0, max >= min, step > 0, all finite,
//! at most max_search_grid_points values.
std::string search_range_problem(const SearchRange& range);
//! Number of grid values of a valid range.
std::size_t search_range_size(const SearchRange& range);
//! The grid values of a valid range, computed as min + i step (no accumulated rounding).
std::vector<double> search_range_values(const SearchRange& range);

inline constexpr std::size_t max_search_grid_points = 10000;     //!< per dimension
inline constexpr std::size_t max_search_evaluations = 20000000;  //!< all four together

//! The default grid brackets the paper's Table 3 design (t 2, R 6, b 8, L 18 mm), which lies on it.
struct HingeSearchSpace {
  SearchRange thickness{0.5e-3, 3.0e-3, 0.1e-3};      //!< t [m]
  SearchRange radius{1.0e-3, 10.0e-3, 0.5e-3};        //!< R [m]
  SearchRange width{4.0e-3, 12.0e-3, 1.0e-3};         //!< b [m]
  SearchRange link_length{10.0e-3, 30.0e-3, 2.0e-3};  //!< L [m]
};

struct SearchConstraints {
  double max_stiffness_ratio = 0.1;       //!< k_m / k_a at most this (Section 2.2: 1/10)
  double min_stress_margin = 2.0;         //!< allowable / sigma_max at x_m at least this
  double max_thickness_to_radius = 1.0;   //!< t / R at most this: keeps Eq. 2 near its thin-neck
                                          //!< range (our choice, not from the paper)
  double min_natural_frequency_Hz = 0.0;  //!< f at least this; 0: no limit
};

enum class SearchRanking { natural_frequency, stress_margin };

struct HingeCandidate {
  HingeParams hinge;
  DesignEvaluation evaluation;
};

struct HingeSearchResult {
  std::size_t evaluated_count = 0;          //!< grid points
  std::size_t geometry_rejected_count = 0;  //!< failed t < 2R, L > 2R or the t/R limit
  std::size_t feasible_count = 0;           //!< met every constraint
  std::vector<HingeCandidate> candidates;   //!< best first, at most max_candidates
};

//! Runs the search. Throws std::invalid_argument for an unsearchable range, a grid of more than
//! max_search_evaluations points, non-positive constraints (a negative frequency floor) or
//! invalid base inputs (actuator, material, mass). Deterministic.
HingeSearchResult search_hinge_designs(const DesignInputs& base, const HingeSearchSpace& space,
                                       const SearchConstraints& constraints,
                                       std::size_t max_candidates,
                                       SearchRanking ranking = SearchRanking::natural_frequency);

}  // namespace piezoshift::design
