// The DAQ's converters and the amplifier against hand calculations.
#include <cmath>

#include <gtest/gtest.h>

#include "piezoshift/plant/amplifier.hpp"
#include "piezoshift/plant/daq.hpp"

namespace piezoshift::plant {
namespace {

TEST(Daq, SixteenBitsOverTenVoltsIsAThirdOfAMillivolt) {
  const DaqParams daq;
  EXPECT_NEAR(daq_lsb_V(daq), 20.0 / 65536.0, 1e-15);  // 0.30518 mV
  EXPECT_NEAR(daq_lsb_V(daq), 0.30518e-3, 1e-8);
}

TEST(Daq, QuantizesToTheNearestCodeAndSaturatesAtTheEndCodes) {
  const DaqParams daq;
  const double q = daq_lsb_V(daq);
  EXPECT_EQ(daq_code(daq, 0.0), 0);
  EXPECT_EQ(daq_code(daq, 0.49 * q), 0);
  EXPECT_EQ(daq_code(daq, 0.51 * q), 1);
  EXPECT_EQ(daq_code(daq, 1.0), 3277);  // 1 V / 0.30518 mV = 3276.8
  EXPECT_EQ(daq_code(daq, 10.0), 32767);
  EXPECT_EQ(daq_code(daq, 25.0), 32767);
  EXPECT_EQ(daq_code(daq, -10.0), -32768);
  EXPECT_EQ(daq_code(daq, -25.0), -32768);
  EXPECT_NEAR(daq_quantize_V(daq, 10.0), 10.0 - q, 1e-12);  // 9.99969 V
  EXPECT_EQ(daq_code(daq, std::nan("")), 0);
}

TEST(Amplifier, CurrentLimitFromSevenWattsIsTwentySixVoltsPerMillisecondIntoTheStack) {
  const AmplifierParams amp;
  EXPECT_NEAR(amplifier_current_limit_A(amp), 7.0 / 150.0, 1e-15);             // 46.7 mA
  EXPECT_NEAR(amplifier_slew_rate_V_per_s(amp, 1.8e-6) * 1e-3, 25.926, 1e-3);  // V/ms
}

TEST(Amplifier, FullStepSlewsAtTheCurrentLimitThenSettles) {
  const AmplifierParams p;
  const double h = 50e-6;
  const Amplifier amp(p, 1.8e-6, h);
  double v = 0.0;
  int steps = 0;
  while (v < 149.0 && steps < 1000) {
    v = amp.step(v, 10.0);
    ++steps;
  }
  // 149 V at 25.9 V/ms, limited in the last few volts by the 3 kHz small-signal response
  const double t_ms = steps * h * 1e3;
  EXPECT_GT(t_ms, 149.0 / 25.926);
  EXPECT_LT(t_ms, 149.0 / 25.926 + 0.3);
  for (int i = 0; i < 200; ++i)
    v = amp.step(v, 10.0);
  EXPECT_NEAR(v, 150.0, 1e-9);
  for (int i = 0; i < 200; ++i)
    v = amp.step(v, 12.0);  // 180 V asked: the output rail holds 150 V
  EXPECT_EQ(v, 150.0);
  for (int i = 0; i < 2000; ++i)
    v = amp.step(v, -3.0);  // negative input: the output stops at 0 V
  EXPECT_EQ(v, 0.0);
}

TEST(Amplifier, SmallStepsFollowTheFirstOrderBandwidthExactly) {
  AmplifierParams p;
  p.small_signal_bandwidth_Hz = 3000.0;
  const double h = 50e-6;
  const Amplifier amp(p, 1.8e-6, h);
  // 0.01 V in = 0.15 V out: far below the slew limit (1.3 V per step)
  double v = 0.0;
  for (int i = 0; i < 4; ++i)
    v = amp.step(v, 0.01);
  const double expected = 0.15 * (1.0 - std::exp(-2.0 * 3.141592653589793 * 3000.0 * 4 * h));
  EXPECT_NEAR(v, expected, 1e-12);
}

}  // namespace
}  // namespace piezoshift::plant
