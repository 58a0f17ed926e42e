#include "piezoshift/design/hinge_search.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace piezoshift::design {
namespace {

bool same_hinge(const HingeParams& a, const HingeParams& b) {
  return std::abs(a.thickness_m - b.thickness_m) < 1e-12 &&
         std::abs(a.radius_m - b.radius_m) < 1e-12 && std::abs(a.width_m - b.width_m) < 1e-12 &&
         std::abs(a.link_length_m - b.link_length_m) < 1e-12;
}

TEST(SearchRange, GridIncludesBothEndsWithoutDrift) {
  const SearchRange t{0.5e-3, 3.0e-3, 0.1e-3};
  EXPECT_EQ(search_range_problem(t), "");
  const auto v = search_range_values(t);
  ASSERT_EQ(v.size(), 26u);
  EXPECT_NEAR(v.back(), 3.0e-3, 1e-15);
  EXPECT_NEAR(v[15], 2.0e-3, 1e-15);
  EXPECT_EQ(search_range_size(SearchRange{1.0, 1.0, 0.5}), 1u);
  EXPECT_NE(search_range_problem(SearchRange{0.0, 1.0, 0.1}), "");
  EXPECT_NE(search_range_problem(SearchRange{2.0, 1.0, 0.1}), "");
  EXPECT_NE(search_range_problem(SearchRange{1.0, 2.0, 0.0}), "");
  EXPECT_NE(search_range_problem(SearchRange{1e-3, 1.0, 1e-6}), "");  // a million values
}

TEST(HingeSearch, EveryCandidateMeetsTheConstraintsAndTheRankingHolds) {
  const SearchConstraints c;
  const HingeSearchResult r = search_hinge_designs({}, HingeSearchSpace{}, c, 1000000);
  EXPECT_EQ(r.evaluated_count, 26u * 19u * 9u * 11u);
  EXPECT_EQ(r.candidates.size(), r.feasible_count);
  EXPECT_GT(r.feasible_count, 100u);
  EXPECT_LT(r.feasible_count + r.geometry_rejected_count, r.evaluated_count);  // some fail
  for (const HingeCandidate& cand : r.candidates) {
    const HingeParams& h = cand.hinge;
    const DesignEvaluation& e = cand.evaluation;
    EXPECT_LT(h.thickness_m, 2.0 * h.radius_m);
    EXPECT_GT(h.link_length_m, 2.0 * h.radius_m);
    EXPECT_LE(h.thickness_m / h.radius_m, c.max_thickness_to_radius);
    EXPECT_LE(e.stiffness_ratio, c.max_stiffness_ratio);
    EXPECT_GE(e.stress_margin, c.min_stress_margin);
    // The candidate's numbers are those of its own hinge.
    DesignInputs in;
    in.hinge = h;
    EXPECT_DOUBLE_EQ(evaluate_design(in).max_stress_at_stroke_Pa, e.max_stress_at_stroke_Pa);
  }
  for (std::size_t i = 1; i < r.candidates.size(); ++i) {
    EXPECT_GE(r.candidates[i - 1].evaluation.natural_frequency_Hz,
              r.candidates[i].evaluation.natural_frequency_Hz);
  }
  // The paper's design (Table 3) lies on the default grid and is feasible: k_m/k_a = 0.0968,
  // margin 7.9.
  const auto paper = std::find_if(r.candidates.begin(), r.candidates.end(),
                                  [](const HingeCandidate& h) { return same_hinge(h.hinge, {}); });
  ASSERT_NE(paper, r.candidates.end());
  EXPECT_NEAR(paper->evaluation.mechanism_stiffness_N_per_um, 6.776, 0.001);
}

TEST(HingeSearch, ThicknessOnlySearchPicksThePaperHinge) {
  // R, b, L fixed at Table 3; k_m grows as t^2.5, so k_m/k_a <= 0.1 allows
  // t <= 2 mm * (7 / 6.776)^(1/2.5) = 2.026 mm; the stiffest feasible on a 0.1 mm grid is 2.0 mm.
  HingeSearchSpace s;
  s.thickness = {1.0e-3, 3.0e-3, 0.1e-3};
  s.radius = {6e-3, 6e-3, 1e-3};
  s.width = {8e-3, 8e-3, 1e-3};
  s.link_length = {18e-3, 18e-3, 1e-3};
  const HingeSearchResult r = search_hinge_designs({}, s, {}, 3);
  EXPECT_EQ(r.evaluated_count, 21u);
  EXPECT_EQ(r.feasible_count, 11u);  // 1.0 to 2.0 mm
  ASSERT_EQ(r.candidates.size(), 3u);
  EXPECT_TRUE(same_hinge(r.candidates[0].hinge, {}));
  EXPECT_NEAR(r.candidates[1].hinge.thickness_m, 1.9e-3, 1e-12);
  EXPECT_NEAR(r.candidates[2].hinge.thickness_m, 1.8e-3, 1e-12);
}

TEST(HingeSearch, RankByMarginWithAFrequencyFloor) {
  SearchConstraints c;
  c.min_natural_frequency_Hz = 1500.0;
  const HingeSearchResult r =
      search_hinge_designs({}, HingeSearchSpace{}, c, 50, SearchRanking::stress_margin);
  ASSERT_EQ(r.candidates.size(), 50u);
  for (std::size_t i = 0; i < r.candidates.size(); ++i) {
    EXPECT_GE(r.candidates[i].evaluation.natural_frequency_Hz, 1500.0);
    if (i > 0) {
      EXPECT_GE(r.candidates[i - 1].evaluation.stress_margin,
                r.candidates[i].evaluation.stress_margin);
    }
  }
  // The most robust fast design is stronger than the paper's (margin 7.94).
  EXPECT_GT(r.candidates[0].evaluation.stress_margin, 7.94);
}

TEST(HingeSearch, ImpossibleMarginLeavesNothing) {
  SearchConstraints c;
  c.min_stress_margin = 1000.0;
  const HingeSearchResult r = search_hinge_designs({}, HingeSearchSpace{}, c, 10);
  EXPECT_EQ(r.feasible_count, 0u);
  EXPECT_TRUE(r.candidates.empty());
}

TEST(HingeSearch, IsDeterministic) {
  const auto a = search_hinge_designs({}, HingeSearchSpace{}, {}, 20);
  const auto b = search_hinge_designs({}, HingeSearchSpace{}, {}, 20);
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (std::size_t i = 0; i < a.candidates.size(); ++i)
    EXPECT_TRUE(a.candidates[i].hinge == b.candidates[i].hinge);
}

TEST(HingeSearch, RejectsBadRangesAndConstraints) {
  HingeSearchSpace s;
  s.radius = {5e-3, 1e-3, 1e-3};
  EXPECT_THROW(search_hinge_designs({}, s, {}, 10), std::invalid_argument);
  SearchConstraints c;
  c.max_stiffness_ratio = 0.0;
  EXPECT_THROW(search_hinge_designs({}, HingeSearchSpace{}, c, 10), std::invalid_argument);
  DesignInputs in;
  in.actuator.stiffness_N_per_um = -70.0;
  EXPECT_THROW(search_hinge_designs(in, HingeSearchSpace{}, {}, 10), std::invalid_argument);
}

}  // namespace
}  // namespace piezoshift::design
