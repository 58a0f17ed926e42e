#include "serve_measure_request.hpp"

#include <exception>
#include <new>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/instrument/sequence_memory.hpp"

namespace piezoshift::app {

namespace {

using nlohmann::json;

MeasureRequestCheck refused(int status, std::string reason) {
  MeasureRequestCheck c;
  c.status = status;
  c.reason = std::move(reason);
  return c;
}

}  // namespace

MeasureRequestCheck check_measure_request(std::string_view body, const MeasureRequestContext& c) {
  json j;
  try {
    j = body.empty() ? json::object() : json::parse(body);
  } catch (const json::exception& e) {
    return refused(400, fmt::format("body is not JSON: {}", e.what()));
  }
  if (!j.is_object())
    return refused(400, R"(expected {"algorithm": "hariharan5", "averages": 1})");
  MeasureRequestCheck out;
  MeasureRequest& req = out.request;
  req.params = c.sequence;
  try {
    const json alg = j.value("algorithm", json("hariharan5"));
    const json avg = j.value("averages", json(1));
    if (!alg.is_string())
      throw core::InputError("algorithm: a name (4step, carre, hariharan5, ...)");
    if (!avg.is_number_integer() || avg.get<long long>() < instrument::kMinAverages ||
        avg.get<long long>() > instrument::kMaxAverages)
      throw core::InputError(fmt::format("averages: a whole number, {} to {}",
                                         instrument::kMinAverages, instrument::kMaxAverages));
    req.algorithm = psi::parse_algorithm(alg.get<std::string>());
    req.params.steps_rad = instrument::commanded_steps(req.algorithm, {}, "algorithm");
    req.params.averages = static_cast<int>(avg.get<long long>());
    if (std::string why = instrument::sequence_problem(req.params); !why.empty())
      throw core::InputError(why);
    if (std::string why =
            instrument::travel_problem(req.params, c.travel_z_max_um, c.calibration_source);
        !why.empty())
      throw core::InputError(why);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {  // core::InputError, json's type errors
    return refused(400, fmt::format("measurement: {}", e.what()));
  }
  // Refused before it starts: its frames are held to the end (a 512 px camera's 100 averages
  // of frame13 ended serve in std::bad_alloc).
  if (std::string why = instrument::sequence_memory_problem(req.params, c.camera); !why.empty())
    return refused(413, fmt::format("measurement: averages and algorithm: {}", why));
  return out;
}

}  // namespace piezoshift::app
