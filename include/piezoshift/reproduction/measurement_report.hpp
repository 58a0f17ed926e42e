#pragma once
// The reproduction report's section "A phase-shifting measurement" (phase_measurement.hpp) and
// its files, beside the report:
//   measurement_surface_nm.png   the measured surface, blue-white-red with its scale bar (the
//                                caption gives the scale in nm)
//   measurement_zernike.png      the Zernike coefficients (gnuplot, with .gp and .dat)
//   measurement_exposures.csv    per frame: the steps commanded, recovered and true, the settle
//                                time, where the plate was over the exposure
// A measurement that is not valid writes no file and its section says why, never a number.
#include <filesystem>

#include "piezoshift/reproduction/document.hpp"
#include "piezoshift/reproduction/phase_measurement.hpp"
#include "piezoshift/reproduction/report.hpp"

namespace piezoshift::reproduction {

//! Writes the files above into dir and lists them in files (figures, data). Throws as
//! write_report does.
void write_measurement_files(const PhaseMeasurement& m, const std::filesystem::path& dir,
                             ReportFiles& files);

//! Appends the section: what was measured, the figures, the error beside the ideal stage's
//! floor, the steps and the settle times, the surface map and the Zernike chart.
void measurement_section(Document& doc, const PhaseMeasurement& m);

}  // namespace piezoshift::reproduction
