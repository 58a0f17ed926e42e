#include "piezoshift/host/servo_parameters.hpp"

#include <cmath>

#include <fmt/core.h>

#include "piezoshift/host/data_recorder.hpp"
#include "piezoshift/host/wave_tables.hpp"
#include "piezoshift/runtime/controller_ranges.hpp"

namespace piezoshift::host {

namespace {

// HPA?'s list, in PI's terms. The first four are controller-wide (PIPython's datarectools reads
// 0x0E000200, 0x16000200 and 0x16000300 to size a recording); the E-727's servo parameters after
// them are per axis on an E-727, one value for all three axes here (one loop drives them).
constexpr ServoParameter kList[] = {
    {0x0E000200, "FLOAT", "Controller", "Servo Update Time (s)"},
    {0x16000200, "INT", "Data Recorder", "Data Recorder Max Points (all tables)"},
    {0x16000300, "INT", "Data Recorder", "Data Recorder Chan Number"},
    {0x13000004, "INT", "Wave Generator", "Max Wave Points (per table)"},
    {ServoParameters::kPTerm, "FLOAT", "Servo", "P Term (the PIDs' kp, per sample)"},
    {ServoParameters::kITerm, "FLOAT", "Servo", "I Term (the PIDs' ki, per sample)"},
    {ServoParameters::kFeedforward, "FLOAT", "Servo", "Feedforward (1: S = A p(Z_d), read-only)"},
    {ServoParameters::kNotchFrequency1, "FLOAT", "Servo", "Notch Frequency 1 (0: none)"},
    {ServoParameters::kNotchFrequency2, "FLOAT", "Servo", "Notch Frequency 2 (0: none)"},
    {ServoParameters::kNotchRejection1, "FLOAT", "Servo", "Notch Rejection 1 (0: none)"},
    {ServoParameters::kNotchRejection2, "FLOAT", "Servo", "Notch Rejection 2 (0: none)"},
    {ServoParameters::kNotchBandwidth1, "FLOAT", "Servo", "Notch Bandwidth 1 (0: none)"},
    {ServoParameters::kNotchBandwidth2, "FLOAT", "Servo", "Notch Bandwidth 2 (0: none)"},
    {ServoParameters::kAnalogTarget, "INT", "Servo", "Analog Target Channel (0: none)"},
};

bool known(long long id) {
  for (const ServoParameter& p : kList)
    if (p.id == id)
      return true;
  return false;
}

}  // namespace

ServoParameters::ServoParameters(const control::SemiClosedLoopParams& controller,
                                 double servo_cycle_s)
    : controller_(controller), servo_cycle_s_(servo_cycle_s) {}

std::span<const ServoParameter> ServoParameters::list() noexcept {
  return kList;
}

std::string ServoParameters::value(long long id) const {
  switch (id) {
    case 0x0E000200:
      return fmt::format("{:.9g}", servo_cycle_s_);
    case 0x16000200:
      return fmt::format("{}", DataRecorder::kTables * DataRecorder::kPoints);
    case 0x16000300:
      return fmt::format("{}", DataRecorder::kTables);
    case 0x13000004:
      return fmt::format("{}", WaveTables::kPoints);
    case kPTerm:
      return fmt::format("{:.12g}", controller_.gains.kp);
    case kITerm:
      return fmt::format("{:.12g}", controller_.gains.ki);
    case kFeedforward:
      return "1";  // the whole calibrated feedforward, always (Eq. 8)
    case kAnalogTarget:
      return "0";  // no analog input sets a target
    default:
      return known(id) ? "0" : std::string{};  // the notch filters: the loop has none
  }
}

GcsError ServoParameters::write(long long id, double value, int level,
                                control::SemiClosedLoopParams& out) const {
  if (!known(id))
    return GcsError::kUnknownParameter;
  // Only the paper's PIDs have a P and an I term; everything else is fixed by the calibration.
  if ((id != kPTerm && id != kITerm) || controller_.kind != control::ControllerKind::kPaper)
    return GcsError::kReadOnlyParameter;
  if (level < 1)
    return GcsError::kParamProtection;
  if (!std::isfinite(value) || value < 0.0)
    return GcsError::kParamOutOfRange;
  out = controller_;
  out.sample_time_s = servo_cycle_s_;
  (id == kPTerm ? out.gains.kp : out.gains.ki) = value;
  return GcsError::kNone;
}

GcsError ServoParameters::check(const control::SemiClosedLoopParams& p) const {
  // The calibration file's check (runtime/controller_ranges.hpp), stability on the nominal inner
  // loop included: gains the loader refuses are refused here too.
  return runtime::controller_problem(p, servo_cycle_s_).empty() ? GcsError::kNone
                                                                : GcsError::kParamOutOfRange;
}

}  // namespace piezoshift::host
