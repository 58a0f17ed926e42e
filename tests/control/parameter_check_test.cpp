// control::params_problem: each problem found from one changed field, against the paper's
// defaults (which the loop runs), and for the firmware's float controller.
#include "piezoshift/control/parameter_check.hpp"

#include <iterator>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace piezoshift::control {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

ParamsProblem problem_of(void (*change)(SemiClosedLoopParams&), double loop_s = 1e-3) {
  SemiClosedLoopParams p{};
  change(p);
  return params_problem(p, loop_s);
}

TEST(ParamsProblem, ThePapersParametersRunAtTheirRate) {
  EXPECT_EQ(params_problem(SemiClosedLoopParams{}, 1e-3), ParamsProblem::kNone);
  // A period given in ns and read back in s (1e6 * 1e-9) is the same rate.
  EXPECT_EQ(params_problem(SemiClosedLoopParams{}, 1e6 * 1e-9), ParamsProblem::kNone);
  EXPECT_STREQ(to_string(ParamsProblem::kNone), "");
  // The firmware's float parameters, and a NaN among them.
  BasicSemiClosedLoopParams<float> f{};
  EXPECT_EQ(params_problem(f, 1e-3F), ParamsProblem::kNone);
  f.gains.kp = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(params_problem(f, 1e-3F), ParamsProblem::kNotFinite);
}

TEST(ParamsProblem, SampleTimes) {
  EXPECT_EQ(problem_of([](SemiClosedLoopParams&) {}, 1e-4), ParamsProblem::kSampleTime);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams&) {}, kNaN), ParamsProblem::kSampleTime);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) { p.sample_time_s = 0.0; }, 0.0),
            ParamsProblem::kSampleTime);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) { p.gains_sample_time_s = 0.0; }),
            ParamsProblem::kSampleTime);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) { p.gains_sample_time_s = kInf; }),
            ParamsProblem::kSampleTime);
}

TEST(ParamsProblem, AnImprovedControllerRunsOnlyAtTheRateItWasDesignedAt) {
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) { p.kind = ControllerKind::kImproved; }),
            ParamsProblem::kNone);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) {
              p.kind = ControllerKind::kImproved;
              p.improved.sample_time_s = 1e-4;
            }),
            ParamsProblem::kImprovedRate);
  // The paper's controller ignores the improved parts.
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) { p.improved.sample_time_s = 1e-4; }),
            ParamsProblem::kNone);
}

TEST(ParamsProblem, EveryNumberInUseMustBeFinite) {
  using Change = void (*)(SemiClosedLoopParams&);
  const Change changes[] = {
      [](SemiClosedLoopParams& p) { p.gains.kp = kNaN; },
      [](SemiClosedLoopParams& p) { p.gains.kd = kInf; },
      [](SemiClosedLoopParams& p) { p.output_max_um = kInf; },
      [](SemiClosedLoopParams& p) { p.deadband_um = kNaN; },
      [](SemiClosedLoopParams& p) { p.derivative_filter = kNaN; },
      [](SemiClosedLoopParams& p) { p.polynomial.p3 = kNaN; },
      [](SemiClosedLoopParams& p) { p.matrix.a[2][1] = -kInf; },
      [](SemiClosedLoopParams& p) { p.scaling[1].sgs_offset_V = kNaN; },
      [](SemiClosedLoopParams& p) { p.scaling[2].drive_V_per_um = kInf; },
      [](SemiClosedLoopParams& p) {
        p.kind = ControllerKind::kImproved;
        p.improved.model[1].operators = 2;
        p.improved.model[1].weight[1] = kNaN;
      },
      [](SemiClosedLoopParams& p) {
        p.kind = ControllerKind::kImproved;
        p.improved.correction_ki = kNaN;
      },
  };
  for (std::size_t k = 0; k < std::size(changes); ++k)
    EXPECT_EQ(problem_of(changes[k]), ParamsProblem::kNotFinite) << "change " << k;
  // A value past the entries in use is not read, so not checked.
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) {
              p.kind = ControllerKind::kImproved;
              p.improved.model[0].weight[5] = kNaN;
            }),
            ParamsProblem::kNone);
}

TEST(ParamsProblem, LimitsScalingAndSizes) {
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) { p.output_min_um = p.output_max_um; }),
            ParamsProblem::kOutputLimits);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) { p.scaling[0].drive_V_per_um = 0.0; }),
            ParamsProblem::kScaling);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) { p.scaling[2].sgs_um_per_V = 0.0; }),
            ParamsProblem::kScaling);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) { p.scaling[1].drive_V_per_um = -0.625; }),
            ParamsProblem::kScaling);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) {
              p.kind = ControllerKind::kImproved;
              p.improved.shaper.taps = kMaxShaperTaps + 1;
            }),
            ParamsProblem::kModelSize);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) {
              p.kind = ControllerKind::kImproved;
              p.improved.model[2].creep_terms = kMaxCreepTerms + 1;
            }),
            ParamsProblem::kModelSize);
  EXPECT_EQ(problem_of([](SemiClosedLoopParams& p) {
              p.kind = ControllerKind::kImproved;
              p.improved.reference_delay_ticks = kMaxReferenceDelayTicks + 1;
            }),
            ParamsProblem::kModelSize);
  for (int k = 1; k <= static_cast<int>(ParamsProblem::kAbsent); ++k)
    EXPECT_GT(std::string(to_string(static_cast<ParamsProblem>(k))).size(), 10u) << k;
}

TEST(SignalScaling, DacToUmInvertsUmToDac) {
  const SignalScaling s{1.6, 0.01, 0.625, -0.02};
  for (double u : {0.0, 1e-3, 5.0, 16.0})
    EXPECT_NEAR(s.dac_to_um(s.um_to_dac(u)), u, 1e-14 * (1.0 + u)) << u;
  EXPECT_NEAR(s.um_to_dac(s.dac_to_um(7.5)), 7.5, 1e-14);
}

}  // namespace
}  // namespace piezoshift::control
