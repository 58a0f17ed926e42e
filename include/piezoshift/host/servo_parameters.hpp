#pragma once
// The parameters SPA?, SEP?, SPA and HPA? know, by PI's ids (docs/gcs.md): the controller-wide
// sizes PIPython's data recorder helper reads, and the E-727's servo parameters that EPICS's
// motorPIGCS2 driver reads for every axis in every poll. Those map to the running loop where it
// has them (P and I gains of the paper's PIDs, writable at command level 1) and are answered
// read-only where it does not (feedforward, notch filters, analog target).
#include <cstddef>
#include <span>
#include <string>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/host/gcs_error.hpp"

namespace piezoshift::host {

struct ServoParameter {
  long long id;
  const char* type;  //!< PI's data type (HPA?)
  const char* group;
  const char* description;
};

class ServoParameters {
 public:
  // The E-727's ids (PI's E-727 parameter list; motorPIGCS2's PIGCS2PiezoCL.h reads these).
  static constexpr long long kPTerm = 0x07000300;
  static constexpr long long kITerm = 0x07000301;
  static constexpr long long kFeedforward = 0x07030600;
  static constexpr long long kNotchFrequency1 = 0x08000100;
  static constexpr long long kNotchFrequency2 = 0x08000101;
  static constexpr long long kNotchRejection1 = 0x07000200;
  static constexpr long long kNotchRejection2 = 0x07000201;
  static constexpr long long kNotchBandwidth1 = 0x08000300;
  static constexpr long long kNotchBandwidth2 = 0x08000301;
  static constexpr long long kAnalogTarget = 0x06000500;
  //! CCL 1's password, as PI documents it for the E-727.
  static constexpr const char* kAdvancedPassword = "advanced";

  ServoParameters(const control::SemiClosedLoopParams& controller, double servo_cycle_s);

  static std::span<const ServoParameter> list() noexcept;
  //! The value as SPA? answers it; empty when the id is not a parameter here.
  std::string value(long long id) const;
  //! Checks `SPA {item} id value` at command level `level`; kNone and `out` = the running set
  //! with the value written, or 54 (unknown), 64 (read-only), 60 (level too low), 17 (not
  //! finite or negative). The set a line's writes make is then checked whole, by check().
  GcsError write(long long id, double value, int level, control::SemiClosedLoopParams& out) const;
  //! kNone, or 17 for a set a calibration file could not hold (runtime::controller_problem at
  //! the servo cycle: e.g. gains unstable on the nominal inner loop, kp 5 and ki 3).
  GcsError check(const control::SemiClosedLoopParams& p) const;
  //! The set the loop now runs (after its kConfigure was applied).
  void applied(const control::SemiClosedLoopParams& p) noexcept { controller_ = p; }
  const control::SemiClosedLoopParams& controller() const noexcept { return controller_; }

 private:
  control::SemiClosedLoopParams controller_;
  double servo_cycle_s_;
};

}  // namespace piezoshift::host
