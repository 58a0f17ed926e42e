#include "piezoshift/procedures/measure_request.hpp"

#include <filesystem>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/procedures/loop_setup.hpp"

namespace piezoshift::procedures {

namespace fs = std::filesystem;

namespace {

// --trigger line needs a DAQ with a trigger output (the twin's, or a Comedi board's
// --trigger-line) and a camera whose line it can reach.
void check_trigger(const MeasureRequest& r) {
  const std::string trigger = option_name(r, "--trigger", "trigger");
  if (r.trigger != "software" && r.trigger != "line")
    throw core::InputError(fmt::format("{} '{}': expected software or line", trigger, r.trigger));
  if (r.trigger == "software" && !r.trigger_line.empty())
    throw core::InputError("--trigger-line: the DAQ's trigger output is used by --trigger line");
  if (r.trigger != "line")
    return;
  if (r.daq != "sim" && r.trigger_line.empty())
    throw core::InputError(fmt::format(
        "--trigger line: DAQ {} has no trigger line (give --trigger-line SUBDEVICE/CHANNEL, a "
        "digital output of the board: 2/0 is the PCI-6229's P0.0)",
        r.daq));
  if (r.camera.starts_with("aravis:Fake"))
    throw core::InputError(fmt::format(
        "{} line: camera {} has no line input (Aravis's fake camera free-runs at 25 Hz on a line "
        "trigger); use {} software",
        trigger, r.camera, trigger));
}

}  // namespace

bool fed_by_twin(const MeasureRequest& r) {
  return r.camera.starts_with("aravis:Fake") && r.daq == "sim";
}

std::string option_name(const MeasureRequest& r, std::string_view cli, std::string_view python) {
  return std::string(r.caller == MeasureCaller::kCli ? cli : python);
}

void validate(const MeasureRequest& r) {
  check_loop_rate(r.rate_Hz, option_name(r, "--rate-hz", "rate_Hz"));
  if (r.averages < instrument::kMinAverages || r.averages > instrument::kMaxAverages)
    throw core::InputError(fmt::format("{} {}: must be {} to {}",
                                       option_name(r, "--averages", "averages"), r.averages,
                                       instrument::kMinAverages, instrument::kMaxAverages));
  check_trigger(r);
  if (r.caller == MeasureCaller::kCli) {
    if (r.out.empty())
      throw core::InputError("--out: a folder for the measurement is required");
    check_measure_out(r.out);
  }
  if (r.camera == "twin" && r.daq != "sim")
    throw core::InputError(
        fmt::format("--camera twin renders the twin's plate: it needs --daq sim, not {}", r.daq));
  if (r.camera != "twin" && !fed_by_twin(r) && !r.surface.empty())
    throw core::InputError(
        fmt::format("{}: the test surface of the twin camera (or of aravis:Fake_1 on --daq sim)",
                    option_name(r, "--surface", "surface")));
  // The twin analyses the pupil it renders.
  if (r.camera == "twin" && (!r.mask_file.empty() || r.mask))
    throw core::InputError(fmt::format(
        "{}: the twin camera renders its own pupil and analyses it; {} is the pupil of other "
        "cameras",
        option_name(r, "--mask", "mask"), option_name(r, "--mask", "mask")));
}

// out must be absent or an empty folder: a measurement never mixes with another's files.
void check_measure_out(const std::string& name) {
  const fs::path out(name);
  std::error_code ec;
  if (!fs::exists(out, ec))
    return;
  if (!fs::is_directory(out, ec) || !fs::is_empty(out, ec))
    throw core::InputError(fmt::format(
        "--out {}: exists and is not an empty folder (a measurement is written whole into a "
        "new one)",
        out.string()));
}

}  // namespace piezoshift::procedures
