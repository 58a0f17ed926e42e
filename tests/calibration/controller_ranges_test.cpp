// The controller's field list (runtime/controller_ranges.hpp): the calibration file's reader
// and writer walk it (every number read back bit for bit), and controller_problem() refuses what
// would make the stage report nonsense or the loop unstable, naming the field.
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/core/bounds.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/runtime/controller_ranges.hpp"
#include "temp_dir_test.hpp"

namespace piezoshift::calibration {
namespace {

using control::SemiClosedLoopParams;
using runtime::controller_problem;
using runtime::kMaxMatrixCondition;
using runtime::kNominalPlantGain;
using runtime::ListField;
using runtime::model_section;
using runtime::nominal_gain_margin_dB;
using runtime::own_sample_time_s;
using runtime::visit_controller_fields;
using runtime::visit_improved_fields;
using runtime::visit_model_fields;

// Every number the list visits, in order, as (section.key[i], value).
struct Collect {
  std::vector<std::pair<std::string, double>> values;
  void operator()(std::string_view section, std::string_view key, const double& v,
                  const core::Bounds&, std::string_view) {
    values.emplace_back(fmt(section, key, -1), v);
  }
  void operator()(std::string_view section, std::string_view key, const std::size_t& v,
                  const core::Bounds&, std::string_view) {
    values.emplace_back(fmt(section, key, -1), static_cast<double>(v));
  }
  template <class Value, class Count>
  void operator()(std::string_view section, std::string_view key, const ListField<Value, Count>& f,
                  const core::Bounds&, std::string_view) {
    for (std::size_t i = 0; i < *f.count; ++i)
      values.emplace_back(fmt(section, key, static_cast<int>(i)), f.values[i]);
  }
  static std::string fmt(std::string_view section, std::string_view key, int i) {
    return std::string(section) + "." + std::string(key) +
           (i >= 0 ? "[" + std::to_string(i) + "]" : "");
  }
};

std::vector<std::pair<std::string, double>> all_numbers(const SemiClosedLoopParams& p) {
  Collect c;
  visit_controller_fields(p, c);
  visit_improved_fields(p.improved, c);
  for (std::size_t i = 0; i < control::kChannels; ++i)
    visit_model_fields(p.improved.model[i], model_section(i), c);
  return c.values;
}

// An improved controller with every list filled and every number an awkward double in range.
SemiClosedLoopParams awkward_improved(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  SemiClosedLoopParams p;
  p.kind = control::ControllerKind::kImproved;
  p.gains = {0.3 + 0.1 * u(rng), 0.05 + 0.05 * u(rng), 0.001 * u(rng)};
  p.gains_sample_time_s = 1e-3;
  control::ImprovedParams& im = p.improved;
  im.sample_time_s = 1e-3;
  im.reference_delay_ticks = 3;
  im.correction_ki = 0.03 * u(rng);
  im.correction_ki_max = 0.3 * u(rng);
  im.correction_boost_error_um = 0.02 * u(rng);
  im.correction_limit_um = 1.0 + u(rng);
  im.shaper.taps = 3;
  im.shaper.weight = {};
  im.shaper.weight[0] = 0.25;
  im.shaper.weight[1] = 0.5;
  im.shaper.weight[2] = 0.25;
  im.shaper.rate_um_per_s = 1e3 * (1.0 + u(rng));
  im.command_slew_um_per_s = 2e3 * (1.0 + u(rng));
  im.slew_approach_um = 0.5 + u(rng);
  for (control::HysteresisCreepParams& m : im.model) {
    m.offset_um = u(rng) - 0.5;
    m.linear_weight = 0.8 + 0.4 * u(rng);
    m.operators = 5;
    for (std::size_t j = 0; j < m.operators; ++j) {
      m.threshold_um[j] = 0.1 * static_cast<double>(j + 1) + 0.01 * u(rng);
      m.weight[j] = u(rng) / 3.0;
    }
    m.creep_terms = 4;
    for (std::size_t k = 0; k < m.creep_terms; ++k)
      m.creep_time_constant_s[k] = std::pow(10.0, static_cast<double>(k)) * (1.0 + u(rng));
    m.creep_gain = 0.01 * (u(rng) - 0.5);
  }
  return p;
}

class ControllerFile : public testing::TempDirTest {};

TEST_F(ControllerFile, EveryNumberOfTheListReadsBackBitForBit) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const SemiClosedLoopParams p = awkward_improved(seed);
    ASSERT_EQ(controller_problem(p, own_sample_time_s(p)), "") << "seed " << seed;
    const std::string file = path("cal.toml");
    write_calibration_file(file, p, "test");
    const SemiClosedLoopParams q = load_calibration_file(file);
    const auto a = all_numbers(p), b = all_numbers(q);
    // 4 controller numbers, 9 improved ones and 3 taps, per channel 2 + 5 + 5 + 4 + 1.
    ASSERT_EQ(a.size(), 4U + 9U + 3U + 3U * 17U);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].first, b[i].first);
      EXPECT_EQ(std::memcmp(&a[i].second, &b[i].second, sizeof(double)), 0)
          << a[i].first << ": " << a[i].second << " read back as " << b[i].second;
    }
  }
}

// Each number of the list set outside its range is named; the reader's own range check (the same
// list) names the file as well.
TEST_F(ControllerFile, EachNumberOutsideItsRangeIsNamed) {
  struct Case {
    const char* key;
    void (*spoil)(SemiClosedLoopParams&);
  };
  const Case cases[] = {
      {"kp", [](SemiClosedLoopParams& p) { p.gains.kp = -0.1; }},
      {"gains_sample_time_s", [](SemiClosedLoopParams& p) { p.gains_sample_time_s = 0.0; }},
      {"correction_ki", [](SemiClosedLoopParams& p) { p.improved.correction_ki = 1.5; }},
      {"shaper_taps[1]", [](SemiClosedLoopParams& p) { p.improved.shaper.weight[1] = -0.5; }},
      {"linear_weight", [](SemiClosedLoopParams& p) { p.improved.model[2].linear_weight = 1e-4; }},
      {"thresholds_um[0]",
       [](SemiClosedLoopParams& p) { p.improved.model[0].threshold_um[0] = 0; }},
      {"creep_gain", [](SemiClosedLoopParams& p) { p.improved.model[1].creep_gain = 0.1; }},
  };
  for (const Case& c : cases) {
    SemiClosedLoopParams p = awkward_improved(7);
    c.spoil(p);
    const std::string why = controller_problem(p, own_sample_time_s(p));
    EXPECT_NE(why.find(c.key), std::string::npos) << c.key << ": " << why;
  }
  // Through the file: written as text, refused at load naming file, section and key.
  const std::string file = write(
      "bad.toml", "[controller]\nkp = 0.6\nki = -0.2\nkd = 0.001\ngains_sample_time_s = 1e-3\n");
  try {
    load_calibration_file(file);
    ADD_FAILURE() << "a negative ki was accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.toml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("ki"), std::string::npos) << e.what();
  }
}

TEST(ControllerProblem, ThePapersControllerAtOneAndTenKilohertzIsAccepted) {
  const SemiClosedLoopParams paper;
  EXPECT_EQ(controller_problem(paper, 1e-3), "");
  EXPECT_EQ(controller_problem(paper, 1e-4), "");  // gains rescaled: kp 0.6, ki 0.02, kd 0.01
}

TEST(ControllerProblem, ACubicThatDoesNotRiseOverTheStrokeIsRefused) {
  SemiClosedLoopParams p;
  p.polynomial = {0.0, 0.0, 0.0, 0.0};  // every Z_d -> 0
  EXPECT_NE(controller_problem(p, 1e-3).find("[controller] p"), std::string::npos);
  // Rising at 0 but falling before 16 um: p'(z) = 1 - 0.01 z^2 is negative past 10 um.
  p.polynomial = {-0.01 / 3.0, 0.0, 1.0, 0.0};
  EXPECT_NE(controller_problem(p, 1e-3).find("slope over the 0 to 16 um stroke"),
            std::string::npos);
  // Within the band over the stroke but falling where the host reads the gauges through it
  // (up to 32 um): p'(z) = 1.5 - 0.0015 z^2 is 1.116 at 16 um and -0.036 at 32 um.
  p.polynomial = {-0.0005, 0.0, 1.5, 0.0};
  EXPECT_NE(controller_problem(p, 1e-3).find("must rise over [-16, 32] um"), std::string::npos);
  p.polynomial = {0.0, 0.0, 1.0, std::numeric_limits<double>::quiet_NaN()};
  EXPECT_NE(controller_problem(p, 1e-3).find("not a finite number"), std::string::npos);
}

TEST(ControllerProblem, AnAThatIsSubnormalSingularOrIllConditionedIsRefused) {
  SemiClosedLoopParams p;
  p.matrix.a = {};
  EXPECT_NE(controller_problem(p, 1e-3).find("condition number"), std::string::npos);
  p.matrix.a = {{{1e-310, 0, 0}, {0, 1e-310, 0}, {0, 0, 1e-310}}};  // POS? answered -nan
  EXPECT_NE(controller_problem(p, 1e-3).find("not a finite, normal number"), std::string::npos);
  p.matrix.a = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 0.5 / kMaxMatrixCondition}}};  // cond = 200
  EXPECT_NE(controller_problem(p, 1e-3).find("condition number 200"), std::string::npos);
  // Rows at unit piston gain (the bands below), the third nearly the mean of the others.
  p.matrix.a = {{{1, 0, 0}, {0, 1, 0}, {0.485, 0.485, 0.03}}};  // cond = 49.0
  EXPECT_EQ(controller_problem(p, 1e-3), "");
  p.matrix.a = {{{1, 0, 0}, {0, 1, 0}, {0.49575, 0.49575, 0.0085}}};  // cond = 175
  EXPECT_NE(controller_problem(p, 1e-3).find("condition number 175"), std::string::npos);
}

// The nominal loop's gain margin against an independent evaluation (a Python script on a
// 200 000-point linear grid, unwrapped phase, the incremental PID's C(z) times z^-2, then
// 20 log10(1 / 0.7) = 3.10 dB for the plant gain): the paper's gains 2.99 + 3.10 dB at 1 kHz and
// 4.15 + 3.10 dB at 10 kHz; kp 1, ki 0.5, kd 0.01 (the stage-1 grid's corner, stable on the twin)
// -2.19 + 3.10 dB; kp 1.8, ki 0.2, kd 0 (which oscillates on the twin) -5.59 + 3.10 dB.
TEST(ControllerProblem, NominalGainMarginMatchesAnIndependentEvaluation) {
  const double plant_dB = 20.0 * std::log10(1.0 / kNominalPlantGain);
  SemiClosedLoopParams p;
  p.sample_time_s = 1e-3;
  EXPECT_NEAR(nominal_gain_margin_dB(p), 2.99 + plant_dB, 0.01);
  p.sample_time_s = 1e-4;
  EXPECT_NEAR(nominal_gain_margin_dB(p), 4.15 + plant_dB, 0.01);
  p.sample_time_s = 1e-3;
  p.gains = {1.0, 0.5, 0.01};
  EXPECT_NEAR(nominal_gain_margin_dB(p), -2.19 + plant_dB, 0.01);
  EXPECT_EQ(controller_problem(p, 1e-3), "");
  p.gains = {1.8, 0.2, 0.0};
  EXPECT_NEAR(nominal_gain_margin_dB(p), -5.59 + plant_dB, 0.01);
  EXPECT_NE(controller_problem(p, 1e-3).find("unstable"), std::string::npos);
}

// kp 5, ki 3, kd 2 ran with the plate swinging between 2.3 and 7.0 um and no fault.
TEST_F(ControllerFile, GainsOutsideTheStableRegionAreRefusedAtLoad) {
  SemiClosedLoopParams p;
  p.gains = {5.0, 3.0, 2.0};
  EXPECT_NE(controller_problem(p, 1e-3).find("unstable on the nominal inner loop"),
            std::string::npos);
  const std::string file = path("unstable.toml");
  write_calibration_file(file, p, "test");
  try {
    load_calibration_file(file);
    ADD_FAILURE() << "kp 5, ki 3, kd 2 was accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unstable.toml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("kp = 5, ki = 3, kd = 2"), std::string::npos) << e.what();
  }
}

// Reproducers: a calibration that loaded drove the plate to full stroke for a 1 um step (p = [0, 0,
// 1000, 0], A x 1000), moved it 2 nm (p or A x 1e-3) without a fault, or advertised a travel of
// 1e308 (TMX?). Each is refused at load naming the file, the key's line and the key.
TEST_F(ControllerFile, AFeedforwardGainOrATravelNoStageHasIsRefusedAtLoadNamingTheLine) {
  const std::string gains = "[controller]\nkp = 0.6\nki = 0.2\nkd = 0.001\n";
  const std::string paper_a =
      "A = [[-0.4218, 0.6030, 0.6547], [0.3482, -0.1491, 0.6962], [0.6321, 0.4397, -0.2980]]\n";
  const struct {
    std::string text;
    const char* where;  // the key's line and column in bad.toml
    const char* piece;
  } bad[] = {
      {gains + "p = [0, 0, 1000, 0]\n", "bad.toml:5:5", "slope over the 0 to 16 um stroke"},
      {gains + "p = [-1.009e-7, 3.89e-7, 1.014e-3, 2.914e-4]\n", "bad.toml:5:5", "runs from 0.000"},
      {gains + "A = [[-421.8, 603.0, 654.7], [348.2, -149.1, 696.2], [632.1, 439.7, -298.0]]\n",
       "bad.toml:5:", "controller.A[0][0]"},
      {gains + "A = [[-4.218e-4, 6.030e-4, 6.547e-4], [3.482e-4, -1.491e-4, 6.962e-4], "
               "[6.321e-4, 4.397e-4, -2.980e-4]]\n",
       "bad.toml:5:5", "row 0 sums to 0.0008359"},
      {gains + "[travel]\nz_max_um = 1e308\n", "bad.toml:6:", "z_max_um"},
      {gains + "[travel]\nz_max_um = 16.5\n", "bad.toml:6:", "z_max_um"},
      {gains + "[travel]\nz_max_um = 11.1\nz_min_um = 17\n", "bad.toml:7:", "z_min_um"},
      {gains + "[travel]\nz_max_um = 11.1\nz_min_um = 11.1\n",
       "bad.toml:7:", "must be below z_max_um"},
  };
  for (const auto& b : bad) {
    const std::string file = write("bad.toml", b.text);
    try {
      load_calibration_file(file);
      ADD_FAILURE() << b.text << " was accepted";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(b.where), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(b.piece), std::string::npos) << e.what();
    }
  }
  // The paper's A and p, and the default twin's travel, load.
  std::optional<double> z_max, z_min;
  load_calibration_file(write("good.toml", gains + paper_a +
                                               "p = [-0.0001009, 0.000389, 1.014, 0.2914]\n"
                                               "[travel]\nz_max_um = 11.1\nz_min_um = 0.05\n"),
                        &z_max, &z_min);
  EXPECT_EQ(z_max, 11.1);
  EXPECT_EQ(z_min, 0.05);
}

// The bands' edges are accepted, beyond them refused (the derivation is in docs/calibration.md).
TEST(ControllerProblem, TheFeedforwardsGainBandsHoldAtTheirEdges) {
  SemiClosedLoopParams p;
  p.polynomial = {0.0, 0.0, 0.5, 0.0};
  EXPECT_EQ(controller_problem(p, 1e-3), "");
  p.polynomial = {0.0, 0.0, 2.0, 0.0};
  EXPECT_EQ(controller_problem(p, 1e-3), "");
  p.polynomial = {0.0, 0.0, 2.01, 0.0};
  EXPECT_NE(controller_problem(p, 1e-3).find("must be in [0.5, 2]"), std::string::npos);
  p.polynomial = {};
  p.matrix.a = {{{0.5, 0, 0}, {0, 0.5, 0}, {0, 0, 0.5}}};
  EXPECT_EQ(controller_problem(p, 1e-3), "");
  p.matrix.a = {{{1.5, 0, 0}, {0, 1.5, 0}, {0, 0, 1.5}}};
  EXPECT_EQ(controller_problem(p, 1e-3), "");
  p.matrix.a = {{{1.5, 0, 0}, {0, 1.6, 0}, {0, 0, 1.5}}};
  EXPECT_NE(controller_problem(p, 1e-3).find("row 1 sums to 1.6"), std::string::npos);
  p.matrix.a = {{{2.5, -1.5, 0}, {0, 1, 0}, {0, 0, 1}}};  // row sum 1, an entry beyond 2
  EXPECT_NE(controller_problem(p, 1e-3).find("A[0][0] = 2.5: must be in [-2, 2]"),
            std::string::npos);
}

// [controller] outer = "fringes" and [fringe_lock]: read into the lock's parameters
// only when the file asks for it, refused by a caller that runs no lock, each bad value named.
TEST_F(ControllerFile, TheFringeLockIsReadWhenTheFileAsksForItAndRefusedWhereNoneRuns) {
  const std::string gains = "[controller]\nkp = 0.6\nki = 0.2\nkd = 0.001\n";
  const std::string locked =
      write("locked.toml", gains +
                               "outer = \"fringes\"\n[fringe_lock]\ngain_per_frame = 0.25\n"
                               "max_step_theta_y_urad = 4.5\nmax_lost_frames = 7\n");
  std::optional<control::FringeLockParams> lock;
  load_calibration_file(locked, nullptr, nullptr, &lock);
  ASSERT_TRUE(lock.has_value());
  EXPECT_EQ(lock->gain_per_frame, 0.25);
  EXPECT_EQ(lock->max_step[2], 4.5);
  EXPECT_EQ(lock->max_lost_frames, 7U);
  // The keys the file does not give keep the lock's own defaults.
  EXPECT_EQ(lock->max_step[0], control::FringeLockParams{}.max_step[0]);
  EXPECT_EQ(lock->max_correction[1], control::FringeLockParams{}.max_correction[1]);
  try {
    load_calibration_file(locked);
    ADD_FAILURE() << "a caller without a lock accepted outer = \"fringes\"";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("piezoshift measure"), std::string::npos) << e.what();
  }
  // Without outer: no lock, and the section alone is refused rather than ignored.
  lock = control::FringeLockParams{};
  load_calibration_file(write("plain.toml", gains), nullptr, nullptr, &lock);
  EXPECT_FALSE(lock.has_value());
  const struct {
    const char* text;
    const char* piece;
  } bad[] = {
      {"[fringe_lock]\ngain_per_frame = 0.3\n", "gain_per_frame: needs [controller] outer"},
      {"outer = \"camera\"\n", "[controller] outer: expected"},
      {"outer = \"fringes\"\n[fringe_lock]\ngain_per_frame = 1.5\n", "gain_per_frame"},
      {"outer = \"fringes\"\n[fringe_lock]\nmax_correction_piston_nm = 100\n",
       "[fringe_lock]: max_correction must be at least max_step"},
      {"outer = \"fringes\"\n[fringe_lock]\nmax_lost_frames = 0\n", "max_lost_frames"},
  };
  for (const auto& b : bad) {
    const std::string file = write("bad.toml", gains + b.text);
    try {
      load_calibration_file(file, nullptr, nullptr, &lock);
      ADD_FAILURE() << b.text << " was accepted";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(b.piece), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.toml"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace piezoshift::calibration
