#pragma once
// The calibration file: what the three calibration stages found, in the form the controller
// loads (`piezoshift calibrate` writes it; `piezoshift run --calibration FILE` and
// `piezoshift reproduce` read it). TOML:
//
//   [controller]
//   kp = 0.6                   # per-sample gains (Eq. 7), Section 4
//   ki = 0.2
//   kd = 0.001
//   gains_sample_time_s = 1e-3 # the T_s the gains were tuned at (Section 4: 1 ms)
//   p = [-0.0001009, 0.000389, 1.014, 0.2914]          # [p3, p2, p1, p0], Eq. 8 (first)
//   A = [[-0.4218, 0.6030, 0.6547],                     # Eq. 8 (second)
//        [0.3482, -0.1491, 0.6962],
//        [0.6321, 0.4397, -0.2980]]
//
//   [travel]                   # optional
//   z_max_um = 11.1            # the travel one move from rest reaches with this controller
//                              # (Section 4.1's search, then single moves); `serve`'s TMX? Z
//   z_min_um = 0.1             # optional: the lowest Z a move from the top reaches (the stacks'
//                              # hysteresis at 0 V); `serve`'s TMN? Z
//
//   [controller] outer = "fringes"   # optional ("none" by default): `measure` runs the fringe
//                                    # lock around the loop (docs/fizeau.md), as with --lock
//   [fringe_lock]              # optional with outer = "fringes": control/fringe_lock.hpp's
//   gain_per_frame = 0.5       # parameters (runtime/controller_ranges.hpp lists them);
//                              # absent keys keep its defaults
//
// Every key is optional (absent: the paper's value, Section 4); an unknown key or section, a
// wrong type or a bad value throws core::InputError naming file, key and reason. The run's own
// sample time is set by the loop, not here. Files are written whole to a temporary file and
// renamed over the old one (io/atomic_file.hpp), with 17 significant digits so that reading
// back gives the same doubles.
#include <optional>
#include <string>

#include "piezoshift/control/fringe_lock.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"

namespace piezoshift::io {
class ConfigFile;
}

namespace piezoshift::calibration {

//! Reads [controller] from an already parsed file into params (does not reject unknown keys).
void read_controller_section(const io::ConfigFile& file, control::SemiClosedLoopParams& params);
//! Loads a file holding [controller] and optionally [travel] and [fringe_lock]; rejects anything
//! else. The travel (empty when the file has none) goes to travel_z_max_um when given; the fringe
//! lock (empty with outer = "none") to fringe_lock, and a file asking for it is refused when
//! fringe_lock is null (the caller runs no lock).
control::SemiClosedLoopParams load_calibration_file(
    const std::string& path, std::optional<double>* travel_z_max_um = nullptr,
    std::optional<double>* travel_z_min_um = nullptr,
    std::optional<control::FringeLockParams>* fringe_lock = nullptr);

//! The file's text; header lines (each prefixed with "# ") describe where it came from.
std::string format_calibration(const control::SemiClosedLoopParams& params,
                               const std::string& header,
                               std::optional<double> travel_z_max_um = std::nullopt,
                               std::optional<double> travel_z_min_um = std::nullopt);
//! Writes format_calibration() atomically; throws core::InputError when the path is not writable.
void write_calibration_file(const std::string& path, const control::SemiClosedLoopParams& params,
                            const std::string& header,
                            std::optional<double> travel_z_max_um = std::nullopt,
                            std::optional<double> travel_z_min_um = std::nullopt);

}  // namespace piezoshift::calibration
