#pragma once
// reproduce's figures (report.hpp): Figures 10 to 12 as the paper draws them, the lambda/8 step
// of both controllers, and the Bode plot of the calibrated PID's loop on each identified plant.
// Private to the module: write_report() draws them and captions them in the report.
#include <filesystem>

#include "piezoshift/io/plot.hpp"
#include "piezoshift/reproduction/report.hpp"
#include "piezoshift/reproduction/reproduction.hpp"

namespace piezoshift::reproduction::detail {

//! The lambda/8 step of both controllers on the true plate's 1 ms exposure means.
io::Figure phase_step_figure(const ReproductionResult& r);
//! The calibrated PID's loop on each identified plant, at each loop rate.
io::Figure inner_loop_figure(const ReproductionResult& r);
//! Figures 10 to 12 and the phase step, and the inner loop's Bode plot when a loop rate was
//! analysed (then true), drawn into dir and listed in files.
bool write_figures(const ReproductionResult& r, const std::filesystem::path& dir,
                   ReportFiles& files);

}  // namespace piezoshift::reproduction::detail
