#pragma once
// What `piezoshift measure` writes (docs/measure.md): into a folder of its own, renamed into
// place only once everything is in it, so a measurement that fails leaves nothing half-written.
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/procedures/measure_outcome.hpp"
#include "piezoshift/psi/grid.hpp"

namespace piezoshift::app {

struct MeasureRecord {
  //! What ran and its figures against the truth (procedures::run_measure's outcome), which
  //! measure_json encodes; the pointers below point into it.
  const procedures::MeasureOutcome* outcome = nullptr;
  const instrument::SequenceParams* params = nullptr;
  const instrument::SequenceResult* sequence = nullptr;
  const instrument::MeasurementAnalysis* analysis = nullptr;
  const psi::Mask* mask = nullptr;
  const psi::Map* truth_nm = nullptr;  //!< the twin camera's surface, else nullptr
  //! The folder the measurement was written to (write_measurement's), "" before.
  std::string out;
  //! --out when something appeared in it while the measurement ran: written beside it instead.
  std::string out_given;
  //! The surface's lateral scale, metres on the plate per pixel (instrument::plate_m_per_px of
  //! the mask and [camera] pupil_radius_m): surface_m.gsf's and surface_nm.datx's. 0: neither
  //! written.
  double m_per_px = 0.0;
};

//! The record of a measurement that has an analysis (kMeasured, kNotConverged); it points into m.
MeasureRecord measure_record(const procedures::MeasureOutcome& m);

//! The summary measure prints with --json and writes as measurement.json:
//! procedures::measure_json of the outcome, with where it was written.
nlohmann::json measure_json(const MeasureRecord& r);

//! Writes the measurement into out (which must not exist, or be an empty folder): frames,
//! surface (.npy, .png, and .gsf and .datx with its lateral scale), truth, mask, exposures.csv,
//! measurement.json, figures and report.md. Built in a sibling folder first and renamed into
//! place at the end. A finished measurement is never discarded: when out has become something
//! else while it ran (a file appeared in it), it goes to the first free of out.1 .. out.99
//! instead, said on stderr and in r.out / r.out_given (measurement.json's "out" and "out_given").
void write_measurement(MeasureRecord& r, const std::string& out);

//! The folder a measurement for `out` goes to now: out when it does not exist or is an empty
//! folder, else the first of out.1 .. out.99 that does not exist; nothing when all are taken.
std::optional<std::filesystem::path> measurement_destination(const std::filesystem::path& out);

}  // namespace piezoshift::app
