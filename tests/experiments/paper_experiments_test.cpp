// The paper's experiments on the shipping loop (bench.hpp), and whether they say they are valid:
// a failure is a failure, never a number. Plants other than the default are where a procedure
// can fail, so they are tested here.
#include "piezoshift/experiments/paper_experiments.hpp"

#include <gtest/gtest.h>

namespace piezoshift::experiments {
namespace {

config::ProjectConfig short_leg_plant() {
  config::ProjectConfig c;
  c.twin.piezo.free_stroke_scale = {1.0, 0.8, 1.0};  // one stack with 80 % of its stroke
  return c;
}

TEST(PaperExperiments, AStepTheShortLegCannotMakeIsNotValidAndSaysWhy) {
  // 11 um needs more than the 80 % stack has: the supervisor trips on saturation.
  StepExperimentOptions o;
  o.record_s = 0.5;
  control::SemiClosedLoopParams c;
  c.polynomial = control::CubicPolynomial::identity();
  const StepExperimentResult r = run_step_response(short_leg_plant(), c, 3, o);
  EXPECT_FALSE(r.validity.valid);
  EXPECT_NE(r.validity.reason.find("saturation"), std::string::npos) << r.validity.reason;
}

TEST(PaperExperiments, TheOracleHoldsThePlateWhereTheGaugeFedLoopCannot) {
  // The paper's own p (p0 = 0.29 um) and A describe the paper's stage, not the twin: fed by the
  // gauges, that controller puts the plate well away from Z_d; fed the plate's truth (oracle,
  // identity polynomial), the same loop puts it within nanometres.
  StepExperimentOptions o;
  o.step_um = 5.0;
  o.record_s = 0.5;
  const config::ProjectConfig config;
  const control::SemiClosedLoopParams paper{};
  const StepExperimentResult gauges = run_step_response(config, paper, 4, o);
  control::SemiClosedLoopParams oracle_params = paper;
  oracle_params.polynomial = control::CubicPolynomial::identity();
  o.bench.feedback = rig::Feedback::kOracle;
  const StepExperimentResult oracle = run_step_response(config, oracle_params, 4, o);
  EXPECT_TRUE(oracle.validity.valid) << oracle.validity.reason;
  EXPECT_NEAR(oracle.metrics.final_um, 5.0, 0.005);
  EXPECT_GT(std::fabs(gauges.metrics.final_um - 5.0), 0.05);
  EXPECT_FALSE(gauges.validity.valid);
  EXPECT_NE(gauges.validity.reason.find("did not reach its target"), std::string::npos);
}

}  // namespace
}  // namespace piezoshift::experiments
