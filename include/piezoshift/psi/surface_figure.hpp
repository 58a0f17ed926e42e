#pragma once
// The false-colour map of a measured surface (io/plot.hpp) with a numbered colour bar in nm: what
// `psi analyze` and `psi simulate` (surface_nm.png/.svg), `measure` (surface_nm.png/.svg) and
// `reproduce`'s measurement (measurement_surface_nm.png/.svg) draw when gnuplot is found.
// Pixels outside the valid area (NaN) are left blank; maps over kMaxSurfaceFigureSide pixels on
// a side are drawn from every k-th pixel (named in the title).
#include <filesystem>
#include <string>

#include "piezoshift/io/plot.hpp"
#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

inline constexpr int kMaxSurfaceFigureSide = 320;

//! The colour scale spans [lo_nm, hi_nm] (a caller's finite_range), Paul Tol's blue-white-red;
//! x and y in camera pixels, one pixel square. title: what the map is, e.g. its RMS and PV.
io::Figure surface_figure(const Map& surface_nm, double lo_nm, double hi_nm, std::string title);

//! <stem>.png and <stem>.svg of surface_figure beside each other (png_path names the PNG) when
//! gnuplot is on PATH; otherwise the PNG alone, as write_false_colour_png draws it (a colour
//! ramp without numbers: the range is in the caller's JSON or report).
void write_surface_map(const std::filesystem::path& png_path, const Map& surface_nm, double lo_nm,
                       double hi_nm, std::string title);

}  // namespace piezoshift::psi
