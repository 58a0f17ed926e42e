#pragma once
// The record of a guided calibration (guided_calibration.hpp): one entry per step of the plan, in
// order, written whole and atomically (io/atomic_file.hpp) after every reading, so that an
// interrupted calibration resumes where it stopped. JSON:
//   {"format": "piezoshift guided calibration session 1",
//    "plan": "<what the plan was made for: DAQ, seed, configuration, stage options>",
//    "steps": 66,
//    "readings": [{"step": 0, "optics": "P1", "reading_um": 0.0123 (null: skipped),
//                  "sgs_um": [..3..], "window_start_s": .., "window_end_s": .., "saturated":
//                  false},
//                 ...]}
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "piezoshift/control/vec3.hpp"

namespace piezoshift::calibration {

struct SessionReading {
  std::size_t step = 0;
  std::string optics;                //!< where the optics were (P1, P2, P3, centre)
  std::optional<double> reading_um;  //!< nothing: a step skipped (a PID at its output limit)
  control::Vec3 sgs_um{};            //!< mean SGS feedback over the window
  double window_start_s = 0.0;
  double window_end_s = 0.0;
  bool saturated = false;
};

struct GuidedSession {
  std::string plan;
  std::size_t steps = 0;
  std::vector<SessionReading> readings;
};

//! Nothing when the file does not exist; core::InputError naming the file for anything malformed
//! (and for a file larger than 16 MiB).
std::optional<GuidedSession> load_guided_session(const std::string& path);
//! Replaces the file atomically; core::InputError naming it when it cannot be written.
void save_guided_session(const std::string& path, const GuidedSession& session);

}  // namespace piezoshift::calibration
