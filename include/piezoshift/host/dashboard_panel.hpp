#pragma once
// A part of the dashboard that `serve` adds from above the host module (the camera's live view
// and the measurement, docs/dashboard.md): the Dashboard hands it the requests under its paths
// and every sample it sees, so the panel adds no path into the loop and no thread to the HTTP
// server's.
#include <string>
#include <string_view>

#include "piezoshift/host/data_recorder.hpp"
#include "piezoshift/host/http_request.hpp"
#include "piezoshift/host/http_server.hpp"
#include "piezoshift/runtime/host_link.hpp"

namespace piezoshift::host {

class DashboardPanel {
 public:
  virtual ~DashboardPanel() = default;
  //! HTTP thread: a request under one of the panel's paths (Dashboard::kPanelPaths). Must not
  //! block: the panel copies what it answers out under a short lock of its own.
  virtual HttpResponse on_request(const HttpRequest& request) = 0;
  //! The thread that drains the samples, with the GCS mutex held: one servo cycle, in order.
  //! Must not block.
  virtual void on_sample(const runtime::HostSample& sample, const RecorderInput& derived) = 0;
};

}  // namespace piezoshift::host
