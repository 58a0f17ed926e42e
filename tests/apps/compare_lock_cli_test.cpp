// `piezoshift compare --lock`: the Fizeau hold of compare's own controllers on seed 1
// (quick schedule, 5 s holds), against an independent path to the same figures: the column's
// controller written to a calibration file, then `piezoshift measure --free-run --hold-s 5
// [--lock] --seed 1` on the same configuration.
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/cli_test.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/reproduction/comparison.hpp"
#include "piezoshift/reproduction/comparison_report.hpp"

namespace piezoshift {
namespace {

using Json = nlohmann::json;
using reproduction::HoldRun;
using reproduction::HoldVariant;
using reproduction::LoopVariant;

class CompareLockCli : public testing::CliTest {};

// One compare, four measures: the holds compare reports are `measure`'s "hold" to the last digit,
// and the lock holds the cavity nearer its set point than the semi-closed loop alone for both
// controllers (measured, seed 1, 5 s: paper 2.49 / 0.57 nm, improved 1.71 / 0.20 nm RMS).
TEST_F(CompareLockCli, TheHoldsAreMeasureOnTheColumnsControllers) {
  reproduction::CompareOptions o;
  o.quick = true;
  o.seeds = {1};
  o.lock = true;
  o.lock_hold_s = 5.0;
  const reproduction::ComparisonResult r = reproduction::compare(config::ProjectConfig{}, o);
  ASSERT_TRUE(r.valid()) << r.invalid_reasons().front();
  const reproduction::SeedComparison& sc = r.seeds.at(0);
  for (const bool improved : {false, true}) {
    const HoldRun& off =
        sc.hold(improved ? HoldVariant::kImprovedUnlocked : HoldVariant::kPaperUnlocked);
    const HoldRun& on =
        sc.hold(improved ? HoldVariant::kImprovedLocked : HoldVariant::kPaperLocked);
    ASSERT_TRUE(off.validity.valid && on.validity.valid)
        << off.validity.reason << on.validity.reason;
    EXPECT_LT(on.path_error_rms_nm, 0.5 * off.path_error_rms_nm) << improved;
    EXPECT_LT(on.path_error_1s_means_rms_nm, off.path_error_1s_means_rms_nm) << improved;
  }

  const std::string cfg = write("hold.toml",
                                "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                "[twin.cavity]\nin_fringes = true\n");
  calibration::write_calibration_file(path("paper.toml"), sc[LoopVariant::kPaper].controller,
                                      "compare's paper column, seed 1");
  calibration::write_calibration_file(path("improved.toml"), sc[LoopVariant::kImproved].controller,
                                      "compare's improved column, seed 1");
  const Json j = reproduction::comparison_json(r);
  for (const HoldVariant v : reproduction::kHoldVariants) {
    const std::string key = reproduction::hold_key(v);
    const std::string cal =
        path(reproduction::hold_of_improved(v) ? "improved.toml" : "paper.toml");
    const testing::CliResult m =
        run("measure --free-run --json --config '" + cfg + "' --calibration '" + cal +
            "' --averages 10 --hold-s 5 --seed 1" +
            (reproduction::hold_locked(v) ? " --lock" : "") + " --out '" + path(key) + "'");
    ASSERT_EQ(m.status, 0) << key << "\n" << m.err;
    const Json hold = Json::parse(m.out)["hold"];
    const HoldRun& h = sc.hold(v);
    EXPECT_EQ(hold["frames"].get<std::size_t>(), h.frames) << key;
    EXPECT_EQ(hold["path_error_rms_nm"].get<double>(), h.path_error_rms_nm) << key;
    EXPECT_EQ(hold["path_error_1s_means_rms_nm"].get<double>(), h.path_error_1s_means_rms_nm)
        << key;
    // One seed: the median is its value, in the JSON under hold_<key>_<figure>.
    EXPECT_EQ(j["hold_" + key + "_path_error_rms_nm"].get<double>(), h.path_error_rms_nm) << key;
    EXPECT_EQ(j["per_seed"][0]["hold_" + key + "_path_error_1s_means_rms_nm"].get<double>(),
              h.path_error_1s_means_rms_nm)
        << key;
  }
  EXPECT_TRUE(j["hold_not_valid"].empty()) << j["hold_not_valid"];
  EXPECT_EQ(j["hold_s"], 5.0);
  EXPECT_EQ(j["hold_improved_locked_within_target"].get<bool>(),
            sc.hold(HoldVariant::kImprovedLocked).path_error_rms_nm <= 0.2);
}

}  // namespace
}  // namespace piezoshift
