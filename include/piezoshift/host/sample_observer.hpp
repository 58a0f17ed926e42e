#pragma once
// Who else sees the loop's samples on the network thread: the GCS interpreter hands each
// HostSample, with the values it derived for its data recorder (poses, channel volts), to one
// observer (the dashboard, docs/dashboard.md), so the web side reads the same stream as the
// recorder and adds no path into the real-time loop.
#include "piezoshift/host/data_recorder.hpp"
#include "piezoshift/runtime/host_link.hpp"

namespace piezoshift::host {

class SampleObserver {
 public:
  virtual ~SampleObserver() = default;
  //! One servo cycle, in order, on the thread that drains the ring; must not block.
  virtual void on_sample(const runtime::HostSample& sample, const RecorderInput& derived) = 0;
};

}  // namespace piezoshift::host
