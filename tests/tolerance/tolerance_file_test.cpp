// Tolerance files: what they name, what they refuse (naming the key), and the draws.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/tolerance/tolerance_file.hpp"

namespace piezoshift::tolerance {
namespace {

const config::ProjectConfig kPaper{};

ToleranceSet parse(const std::string& text) {
  return parse_tolerances(text, "tol.toml", kPaper);
}

// The message of the InputError parse() throws, or "" when it does not.
std::string refusal(const std::string& text) {
  try {
    parse(text);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ToleranceFile, NamesDesignAndPerLegTwinParameters) {
  const ToleranceSet set = parse(R"(
[tolerance.hinge.thickness_m]
distribution = "uniform"
lo = -5e-6
hi = 5e-6
source = "wire EDM"
[tolerance.twin.piezo.free_stroke_scale]
distribution = "normal"
sigma = 0.02
bound = 0.05
relative = true
source = "one batch"
)");
  ASSERT_EQ(set.tolerances.size(), 4U);  // t, then the three legs
  EXPECT_EQ(set.tolerances[0].key, "hinge.thickness_m");
  EXPECT_EQ(set.tolerances[0].nominal, 2e-3);
  EXPECT_EQ(set.tolerances[0].source, "wire EDM");
  EXPECT_EQ(set.tolerances[2].key, "twin.piezo.free_stroke_scale[1]");
  EXPECT_EQ(set.tolerances[2].nominal, 0.875);  // configs/paper.toml's second stack
  EXPECT_DOUBLE_EQ(set.tolerances[2].value_at(0.1), 0.875 * 1.1);
  EXPECT_EQ(set.tolerances[2].distribution.describe(), "normal sigma 0.02 bound ±0.05 (relative)");
}

TEST(ToleranceFile, AnUnknownParameterIsRefusedByItsKey) {
  const std::string why = refusal(R"(
[tolerance.hinge.thicknes_m]
distribution = "uniform"
lo = -5e-6
hi = 5e-6
source = "typo"
)");
  EXPECT_NE(why.find("tol.toml"), std::string::npos) << why;
  EXPECT_NE(why.find("tolerance.hinge.thicknes_m"), std::string::npos) << why;
}

TEST(ToleranceFile, ARangeBeyondTheParametersValidRangeIsRefused) {
  // 45 steel's Poisson ratio is in [0, 0.5): 0.28 + 0.3 is not.
  const std::string why = refusal(R"(
[tolerance.material.poisson_ratio]
distribution = "uniform"
lo = -0.01
hi = 0.3
source = "x"
)");
  EXPECT_NE(why.find("[tolerance.material.poisson_ratio]"), std::string::npos) << why;
  EXPECT_NE(why.find("valid range"), std::string::npos) << why;
  EXPECT_NE(why.find("material.poisson_ratio = 0.58"), std::string::npos) << why;
}

TEST(ToleranceFile, DistributionsThatCannotBeSampledAreRefused) {
  const auto with = [](const std::string& body) {
    return refusal("[tolerance.hinge.radius_m]\nsource = \"x\"\n" + body);
  };
  EXPECT_NE(with("distribution = \"uniform\"\nlo = 1e-6\nhi = -1e-6\n").find("lo 1e-06 > hi"),
            std::string::npos);
  EXPECT_NE(with("distribution = \"normal\"\nsigma = 0\nbound = 1e-6\n").find("cannot be sampled"),
            std::string::npos);
  EXPECT_NE(with("distribution = \"normal\"\nsigma = 1e-6\nbound = 1e-8\n").find("bound >= 0.1"),
            std::string::npos);
  EXPECT_NE(with("distribution = \"triangle\"\nlo = 0\nhi = 0\n").find("\"triangle\" cannot be"),
            std::string::npos);
  EXPECT_NE(with("distribution = \"uniform\"\nlo = 0\n").find("needs hi"), std::string::npos);
  EXPECT_NE(with("distribution = \"discrete\"\n").find("needs values"), std::string::npos);
  // Every refusal names the parameter's section.
  EXPECT_NE(with("distribution = \"discrete\"\n").find("[tolerance.hinge.radius_m]"),
            std::string::npos);
  // Relative to a nominal 0 (the first leg's height error) would vary nothing.
  EXPECT_NE(refusal("[tolerance.twin.geometry.height_errors_um]\ndistribution = \"uniform\"\n"
                    "lo = -0.1\nhi = 0.1\nrelative = true\nsource = \"x\"\n")
                .find("twin.geometry.height_errors_um[0] (nominal 0) would vary nothing"),
            std::string::npos);
  // A tolerance without its source, and an integer parameter, are refused too.
  EXPECT_NE(refusal("[tolerance.hinge.radius_m]\ndistribution = \"uniform\"\nlo = 0\nhi = 0\n")
                .find("source missing"),
            std::string::npos);
  EXPECT_NE(refusal("[tolerance.twin.daq.resolution_bits]\ndistribution = \"discrete\"\nvalues = "
                    "[0]\nsource = \"x\"\n")
                .find("not a number with a tolerance"),
            std::string::npos);
}

TEST(ToleranceFile, DrawsDependOnSeedAndIndexAloneAndStayWithinTheirBounds) {
  const ToleranceSet set = parse(R"(
[tolerance.hinge.thickness_m]
distribution = "uniform"
lo = -5e-6
hi = 5e-6
source = "a"
[tolerance.hinge.radius_m]
distribution = "normal"
sigma = 2e-6
bound = 3e-6
source = "b"
[tolerance.hinge.width_m]
distribution = "discrete"
values = [-1e-5, 0.0, 1e-5]
source = "c"
)");
  // The set is in the range lists' order (width, thickness, radius), not the file's.
  ASSERT_EQ(set.tolerances.size(), 3U);
  ASSERT_EQ(set.tolerances[0].key, "hinge.width_m");
  ASSERT_EQ(set.tolerances[1].key, "hinge.thickness_m");
  EXPECT_EQ(draw_deviations(set, 7, 123), draw_deviations(set, 7, 123));
  EXPECT_NE(draw_deviations(set, 7, 123), draw_deviations(set, 7, 124));
  EXPECT_NE(draw_deviations(set, 8, 123), draw_deviations(set, 7, 123));
  double sum_sq = 0.0, max_abs = 0.0;
  int zeros = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const std::vector<double> d = draw_deviations(set, 1, static_cast<std::uint64_t>(i));
    const double width = d[0], thickness = d[1], radius = d[2];
    ASSERT_GE(thickness, -5e-6);
    ASSERT_LE(thickness, 5e-6);
    max_abs = std::max(max_abs, std::abs(radius));
    sum_sq += radius * radius;
    ASSERT_TRUE(width == -1e-5 || width == 0.0 || width == 1e-5) << width;
    zeros += width == 0.0 ? 1 : 0;
  }
  EXPECT_LE(max_abs, 3e-6);
  EXPECT_GT(max_abs, 2.8e-6);  // the tails reach the bound
  // A normal truncated at 1.5 sigma has sigma 0.7375 of the untruncated one.
  EXPECT_NEAR(std::sqrt(sum_sq / n), 0.7375 * 2e-6, 0.04e-6);
  EXPECT_NEAR(zeros, n / 3, 100);
}

TEST(ToleranceFile, ApplyingDeviationsSetsTheValuesAndReportsAnUnbuildableHinge) {
  const ToleranceSet set = parse(R"(
[tolerance.hinge.thickness_m]
distribution = "uniform"
lo = -1e-3
hi = 11e-3
source = "a"
)");
  config::ProjectConfig c = kPaper;
  EXPECT_EQ(apply_deviations(set, {1e-5}, c), "");
  EXPECT_DOUBLE_EQ(c.design.hinge.thickness_m, 2.01e-3);
  c = kPaper;  // t = 13 mm against R = 6 mm: t < 2R fails
  EXPECT_NE(apply_deviations(set, {11e-3}, c), "");
}

}  // namespace
}  // namespace piezoshift::tolerance
