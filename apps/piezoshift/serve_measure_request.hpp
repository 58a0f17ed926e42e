#pragma once
// The body of the dashboard's POST /api/measure (serve_camera.hpp) checked before a measurement
// starts: {"algorithm": "hariharan5", "averages": 1}, both optional. The fuzz target
// `measure_request` (fuzz/) calls it as serve does.
#include <optional>
#include <string>
#include <string_view>

#include "piezoshift/camera/settings.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/psi/phase_algorithms.hpp"

namespace piezoshift::app {

//! What serve needs besides the body to judge it.
struct MeasureRequestContext {
  instrument::SequenceParams sequence;  //!< base, settle criterion, timeouts
  std::optional<double> travel_z_max_um;
  std::string calibration_source;
  camera::CameraSettings camera;  //!< the frames' size, for the memory bound
};

struct MeasureRequest {
  psi::Algorithm algorithm = psi::Algorithm::kHariharan5;
  instrument::SequenceParams params;
};

//! The request, or an HTTP status and why not: 400 for a body that is not the JSON above or a
//! value out of range (algorithm, averages 1 to 100, the travel), 413 for a measurement beyond
//! instrument::sequence_memory_problem's bound. Never throws for any body (std::bad_alloc aside).
struct MeasureRequestCheck {
  int status = 200;
  std::string reason;  //!< "" when status is 200
  MeasureRequest request;
};

MeasureRequestCheck check_measure_request(std::string_view body, const MeasureRequestContext& c);

}  // namespace piezoshift::app
