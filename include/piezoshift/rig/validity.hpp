#pragma once
// Whether an experiment measured what it claims to. A failure is a failure, never a number: an
// experiment whose supervisor tripped, whose PID sat at its output limit where it was measured,
// that did not reach its target or whose step never settled says so here, with the first reason,
// and every report (JSON, Markdown, the exit status of `reproduce`) shows it.
#include <stdexcept>
#include <string>

namespace piezoshift::rig {

struct Validity {
  bool valid = true;
  std::string reason;  //!< the first reason it is not valid ("" when valid)

  //! Marks it invalid; the first reason is kept.
  void fail(const std::string& why) {
    if (valid)
      reason = why;
    valid = false;
  }
};

//! Thrown by a procedure that cannot go on (a calibration stage whose supervisor tripped): the
//! program reports it and exits with status 4, as `reproduce` does for a result not valid.
class ProcedureFailed : public std::runtime_error {
 public:
  explicit ProcedureFailed(const std::string& why) : std::runtime_error(why) {}
};

//! The exit status of a procedure or experiment that is not valid (docs/experiments.md; 2 stays
//! bad input, 3 a supervisor fault of `run` and `simulate`).
inline constexpr int kExitNotValid = 4;

}  // namespace piezoshift::rig
