#pragma once
// Whether an experiment measured what it claims to. A failure is a failure, never a number: an
// experiment whose supervisor tripped, whose PID sat at its output limit where it was measured,
// that did not reach its target or whose step never settled says so here, with the first reason,
// and every report (JSON, Markdown, the exit status of `reproduce`) shows it.
#include <string>

namespace piezoshift::experiments {

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

}  // namespace piezoshift::experiments
