#pragma once
// Figures drawn by gnuplot (Debian package gnuplot-nox). render() writes, beside each other,
//   <stem>.dat  the data, one gnuplot "index" block per series;
//   <stem>.gp   a gnuplot script that reads <stem>.dat by its relative name, so a user can edit
//               the style and run `gnuplot <stem>.gp` in that folder to redraw;
//   <stem>.png  (pngcairo, width_px x height_px pixels) and/or <stem>.svg,
// by running gnuplot (found on PATH) in the output folder.
//
//   io::Figure f;
//   f.panels.push_back({.title = "Step response", .x_label = "time [s]", .y_label = "z [um]"});
//   f.panels[0].series.push_back(io::line_series("measured", t_s, z_um));
//   f.panels[0].series.push_back(io::band_series("+-2 %", t0, t1, 10.78, 11.22));
//   io::render(f, "out/step");            // out/step.{dat,gp,png}
//
// Several panels form a grid (rows x cols, filled row by row): enough for a time series with a
// tolerance band, an x-y curve above its error curve, and histograms side by side.
// Not real-time safe. Text is drawn as written (gnuplot's "enhanced" markup is off, so names
// like s1_um print literally).
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace piezoshift::io {

//! gnuplot missing or failing, or an output file that cannot be written.
class PlotError : public std::runtime_error {
 public:
  explicit PlotError(const std::string& message) : std::runtime_error(message) {}
};

enum class SeriesStyle {
  kLines,
  kPoints,
  kLinesPoints,
  kBoxes,  //!< bars centred on x, height y, width w (histograms)
  kBand,   //!< filled area between y (lower edge) and w (upper edge) over x
};

struct Series {
  std::string title;  //!< legend entry; empty: none
  SeriesStyle style = SeriesStyle::kLines;
  std::vector<double> x;
  std::vector<double> y;
  std::vector<double> w;  //!< kBoxes: box widths; kBand: upper edges; otherwise unused (empty)
  std::string color;      //!< "#rrggbb"; empty: the next colour of the default cycle
  double line_width = 1.5;
};

//! A straight reference line across the whole panel, drawn dashed: x = at or y = at.
struct Marker {
  bool vertical = true;
  double at = 0.0;
  std::string label;  //!< written beside the line; empty: none
};

struct Panel {
  std::string title;
  std::string x_label;  //!< with its unit, e.g. "time [s]"
  std::string y_label;
  std::vector<Series> series;
  std::vector<Marker> markers;
  std::optional<std::pair<double, double>> x_range;  //!< empty: autoscale
  std::optional<std::pair<double, double>> y_range;
  std::string key = "top right";  //!< gnuplot legend placement; "off" hides the legend
  bool x_log = false;             //!< logarithmic x axis (Bode plots); every x must be > 0
};

struct Figure {
  std::string title;  //!< over the whole figure; empty: none
  int rows = 1;       //!< panel grid; rows * cols must hold all panels
  int cols = 1;
  std::vector<Panel> panels;
  int width_px = 800;  //!< PNG size in pixels (the SVG gets the same size in points)
  int height_px = 600;
  bool png = true;
  bool svg = false;
};

struct PlotOptions {
  std::string gnuplot = "gnuplot";  //!< program name (searched on PATH) or a path to it
};

struct PlotFiles {
  std::filesystem::path data;
  std::filesystem::path script;
  std::optional<std::filesystem::path> png;
  std::optional<std::filesystem::path> svg;
};

//! Writes <stem>.dat and <stem>.gp and runs gnuplot to draw the requested formats. Creates the
//! folder of stem if needed. Throws std::invalid_argument for an inconsistent figure (series
//! sizes, grid too small), InputError for a stem that names no file, and PlotError when gnuplot is
//! not found, fails (its messages are in the error), or leaves an empty output file.
PlotFiles render(const Figure& figure, const std::filesystem::path& stem,
                 const PlotOptions& options = {});

//! Refuses, with an InputError naming `option` and the path, an output path that names no file
//! ("dir/", ".", "..") or whose folder cannot take a file: the nearest folder on
//! its way that exists must be a folder in which a file can be created (tried, then removed).
//! For a command to call on its option before its work; render() checks the name again.
void check_output_path(const std::filesystem::path& path, std::string_view option);

//! Writes only <stem>.dat and <stem>.gp (no gnuplot needed); returns their paths.
PlotFiles write_plot_files(const Figure& figure, const std::filesystem::path& stem);

//! The full path of the gnuplot program, or nothing when it is not on PATH.
std::optional<std::filesystem::path> find_gnuplot(std::string_view program = "gnuplot");

//! A polyline through (x[i], y[i]).
Series line_series(std::string title, std::span<const double> x, std::span<const double> y,
                   std::string color = {});
//! Markers at (x[i], y[i]).
Series point_series(std::string title, std::span<const double> x, std::span<const double> y,
                    std::string color = {});
//! A horizontal band y_lo <= y <= y_hi from x_lo to x_hi (a tolerance band).
Series band_series(std::string title, double x_lo, double x_hi, double y_lo, double y_hi,
                   std::string color = {});
//! Histogram of values in bins of width bin_width whose edges are integer multiples of
//! bin_width (so two histograms with the same width line up); counts per bin as kBoxes.
//! Non-finite values are an error (std::invalid_argument), as is bin_width <= 0 or a bin count
//! over 10000.
Series histogram_series(std::string title, std::span<const double> values, double bin_width,
                        std::string color = {});

}  // namespace piezoshift::io
