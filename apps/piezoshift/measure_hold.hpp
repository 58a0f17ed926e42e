#pragma once
// The hold after a measurement (`measure --hold-s`, docs/measure.md): the stage kept at frame 0
// while the camera exposes frame after frame, each exposure's record (its frame is not kept) and
// the cavity's path from its set point on the twin, written as hold.csv, hold.png and a summary.
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "piezoshift/instrument/sequence.hpp"

namespace piezoshift::app {

//! One row of report.md's table.
std::string hold_markdown(const instrument::SequenceResult& s);

//! hold.csv, and hold.png/svg when gnuplot is there, into dir.
void write_hold(const instrument::SequenceResult& s, const std::filesystem::path& dir);

}  // namespace piezoshift::app
