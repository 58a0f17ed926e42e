// The measure procedure (procedures/measure_*.hpp) as both front ends run it: the request's one
// validation in the caller's words, a measurement on the twin and its one encoder.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/procedures/measure_json.hpp"
#include "piezoshift/procedures/measure_request.hpp"
#include "piezoshift/procedures/measure_run.hpp"
#include "temp_dir_test.hpp"

namespace piezoshift::procedures {
namespace {

std::string refusal(const MeasureRequest& r) {
  try {
    validate(r);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MeasureRequestTest, RefusalsNameTheCallersOption) {
  MeasureRequest cli;
  cli.out = "m";
  cli.rate_Hz = 500.0;
  EXPECT_EQ(refusal(cli), "--rate-hz 500: supported rates are 1000 to 10000 Hz");
  MeasureRequest py;
  py.caller = MeasureCaller::kPython;
  py.rate_Hz = 500.0;
  EXPECT_EQ(refusal(py), "rate_Hz 500: supported rates are 1000 to 10000 Hz");
  py.rate_Hz = 1000.0;
  py.averages = instrument::kMaxAverages + 1;
  EXPECT_EQ(refusal(py), "averages 101: must be 1 to 100");
  py.averages = instrument::kMinAverages;
  py.trigger = "sideways";
  EXPECT_EQ(refusal(py), "trigger 'sideways': expected software or line");
  py.trigger = "software";
  py.mask = psi::Mask(4, 4, 1);
  EXPECT_EQ(refusal(py),
            "mask: the twin camera renders its own pupil and analyses it; mask is the pupil of "
            "other cameras");
  py.mask.reset();
  EXPECT_EQ(refusal(py), "");  // Python writes no folder: no out to check
}

TEST(MeasureRequestTest, TheCliNeedsAFreshOutFolder) {
  MeasureRequest cli;
  EXPECT_EQ(refusal(cli), "--out: a folder for the measurement is required");
  cli.out = std::filesystem::temp_directory_path().string();  // exists, not empty
  EXPECT_NE(refusal(cli).find("exists and is not an empty folder"), std::string::npos);
}

// The paper's controller as given (Section 4), so that no start-up calibration runs first.
class MeasureRunTest : public testing::TempDirTest {
 protected:
  MeasureRequest request() {
    MeasureRequest r;
    r.caller = MeasureCaller::kPython;
    r.free_run = true;
    r.controller = control::SemiClosedLoopParams{};
    r.config_file = write("cam.toml", "[camera]\nwidth_px = 96\nheight_px = 96\n");
    return r;
  }
};

TEST_F(MeasureRunTest, OnTheTwinTheOutcomeAndItsJsonAgree) {
  MeasureRequest r = request();
  r.seed = 2;
  const MeasureOutcome m = run_measure(r);
  ASSERT_EQ(m.end, MeasureEnd::kMeasured) << m.reason;
  ASSERT_TRUE(m.analysis);
  EXPECT_EQ(m.params.wavelength_nm, core::kHeNeWavelength_nm);
  EXPECT_EQ(m.camera, "twin");
  EXPECT_EQ(m.daq, "sim");
  EXPECT_EQ(m.calibration_source, "a controller from Python");
  EXPECT_FALSE(m.real_time);
  const nlohmann::json j = measure_json(m);
  EXPECT_EQ(j["clock"], "free-run");
  EXPECT_EQ(j["frames"], 5);
  EXPECT_EQ(j["exposures"].size(), 5u);
  EXPECT_EQ(j["surface_rms_nm"].get<double>(), m.analysis->figures.rms);
  ASSERT_TRUE(m.error_rms_nm && m.floor_error_rms_nm);
  EXPECT_LT(*m.error_rms_nm, 1.0);
  EXPECT_EQ(j["error_rms_nm"].get<double>(), *m.error_rms_nm);
  EXPECT_EQ(j["stage_error_rms_nm"].get<double>(),
            stage_error_rms_nm(*m.error_rms_nm, *m.floor_error_rms_nm));
  EXPECT_FALSE(j.contains("out"));
  EXPECT_EQ(measure_json(m, {.out = "m", .out_given = ""})["out"], "m");
}

TEST_F(MeasureRunTest, ASequenceThatCannotSettleIsAnOutcomeNotAnException) {
  MeasureRequest r = request();
  r.on_target.band_nm = 1e-6;
  r.on_target.timeout_s = 0.05;
  const MeasureOutcome m = run_measure(r);
  EXPECT_EQ(m.end, MeasureEnd::kNotValid);
  EXPECT_NE(m.reason.find("measure: "), std::string::npos);
  EXPECT_NE(m.reason.find("did not settle"), std::string::npos);
  const nlohmann::json j = measure_json(m);
  EXPECT_EQ(j, (nlohmann::json{{"valid", false}, {"reason", m.sequence.validity.reason}}));
}

}  // namespace
}  // namespace piezoshift::procedures
