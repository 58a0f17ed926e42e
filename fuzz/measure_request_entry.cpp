// The measure_request target: the body of the dashboard's POST /api/measure through serve's own
// check (apps/piezoshift/serve_measure_request.hpp), on a 256 px camera as serve's default.
#include <stdexcept>
#include <string>

#include "entry_points.hpp"
#include "piezoshift/instrument/sequence_memory.hpp"
#include "serve_measure_request.hpp"

namespace piezoshift::fuzz {

void measure_request_input(std::string_view data) {
  app::MeasureRequestContext c;
  c.travel_z_max_um = 10.0;
  c.calibration_source = "the fuzz target's";
  const app::MeasureRequestCheck r = app::check_measure_request(data, c);
  // What is accepted runs: it must be a sequence within every bound; a refusal has a reason.
  if (r.status == 200 &&
      (!instrument::sequence_problem(r.request.params).empty() ||
       !instrument::sequence_memory_problem(r.request.params, c.camera).empty() ||
       !instrument::travel_problem(r.request.params, c.travel_z_max_um, c.calibration_source)
            .empty()))
    throw std::logic_error("measure_request: a request beyond its bounds was accepted");
  if (r.status != 200 && ((r.status != 400 && r.status != 413) || r.reason.empty()))
    throw std::logic_error("measure_request: refused with status " + std::to_string(r.status) +
                           " and reason '" + r.reason + "'");
}

}  // namespace piezoshift::fuzz
