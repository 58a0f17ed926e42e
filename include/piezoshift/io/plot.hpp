#pragma once
// Figures drawn by gnuplot (Debian package gnuplot-nox). render() writes, beside each other,
//   <stem>.dat  the data, one gnuplot "index" block per series;
//   <stem>.gp   a gnuplot script that reads <stem>.dat by its relative name, so a user can edit
//               the style and run `gnuplot <stem>.gp` in that folder to redraw;
//   <stem>.svg  (width_px x height_px points) and <stem>.png (pngcairo at print resolution:
//               png_scale times the points, 2000 px for an 800 pt wide figure),
// by running gnuplot (found on PATH) in the output folder.
//
//   io::Figure f;
//   f.panels.push_back({.x_label = "time [s]", .y_label = "z [µm]"});
//   f.panels[0].series.push_back(io::line_series("measured", t_s, z_um));
//   f.panels[0].series.push_back(io::band_series("±2 %", t0, t1, 10.78, 11.22));
//   io::render(f, "out/step");            // out/step.{dat,gp,svg,png}
//
// The house style lives here and nowhere else (plot.cpp): one sans font, the Okabe-Ito colour
// cycle with a dash pattern and a point shape per series (so series stay apart in greyscale and
// for colour-blind readers), the legend below the data, marker labels and annotations on an
// opaque box in front of the curves, tolerance bands with their edges drawn over the curves, and
// UTF-8 text: write units as µm, nm, ±, λ, σ, °, and give every axis label its unit in brackets.
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
  kBand,   //!< filled area between y (lower edge) and w (upper edge) over x, edges drawn dashed
  kImage,  //!< a map: value w at pixel (x, y) of a regular grid, row by row; Panel::cb_label
};

struct Series {
  std::string title;  //!< legend entry; empty: none
  SeriesStyle style = SeriesStyle::kLines;
  std::vector<double> x;
  std::vector<double> y;
  std::vector<double> w;  //!< kBoxes: box widths; kBand: upper edges; otherwise unused (empty)
  std::string color;      //!< "#rrggbb"; empty: the next colour of the default cycle
  double line_width = 1.5;
  //! gnuplot dash pattern, "solid" or e.g. "(6,3)"; empty: the next pattern of the cycle, which
  //! advances with the colour (the first series of a panel is solid)
  std::string dash;
};

//! A straight reference line across the whole panel, drawn dashed: x = at or y = at.
struct Marker {
  bool vertical = true;
  double at = 0.0;
  std::string label;  //!< written beside the line; empty: none
  //! where along the line the label sits, as a fraction of the panel (0 bottom/left, 1 top/right):
  //! two markers close together get different heights so their labels do not merge
  double label_at = 0.06;
};

//! Text placed on a panel: a key number next to what it is about.
struct Label {
  double x = 0.0;  //!< position, in graph fractions (0..1) or, with data_coords, in data units
  double y = 0.0;
  std::string text;
  bool data_coords = false;
  std::string align = "left";  //!< left, center or right: which end of the text is at (x, y)
};

struct Panel {
  std::string title;
  std::string x_label;  //!< with its unit, e.g. "time [s]"
  std::string y_label;
  std::vector<Series> series;
  std::vector<Marker> markers;
  std::vector<Label> labels;
  std::optional<std::pair<double, double>> x_range;  //!< empty: autoscale
  std::optional<std::pair<double, double>> y_range;
  //! gnuplot legend placement, outside the data by default; "off" hides the legend
  std::string key = "below";
  bool x_log = false;    //!< logarithmic x axis (Bode plots); every x must be > 0
  std::string cb_label;  //!< colour bar of a kImage panel, with unit
  std::optional<std::pair<double, double>> cb_range;  //!< kImage colour scale; empty: autoscale
  bool equal_axes = false;                            //!< one x unit as long as one y unit (maps)
};

struct Figure {
  std::string title;  //!< over the whole figure; empty: none
  int rows = 1;       //!< panel grid; rows * cols must hold all panels
  int cols = 1;
  std::vector<Panel> panels;
  int width_px = 800;  //!< layout size: the SVG's in points, the PNG's in pixels / png_scale
  int height_px = 600;
  bool png = true;
  bool svg = true;
  //! PNG pixels per point: 2.5 draws an 800 pt figure 2000 px wide (300 dpi at 17 cm), with
  //! fonts, lines and points scaled alike so the PNG looks like the SVG
  double png_scale = 2.5;
  //! one line a report prints under the figure (what it shows and its key numbers)
  std::string caption;
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

//! Writes <stem>.dat and <stem>.gp and runs gnuplot to draw the requested formats. The folder of
//! stem must exist (it is never created). The side files are replaced atomically
//! (io::write_file_atomically: a fresh temporary, O_EXCL | O_NOFOLLOW, renamed over the name),
//! and what is at the images' and the log's names is removed before gnuplot runs, so a link
//! planted at any of the names is replaced, never written through. Throws std::invalid_argument
//! for an inconsistent figure (series sizes, grid too small), InputError for a stem that names no
//! file, holds a control character or whose folder does not exist, and PlotError when gnuplot is
//! not found, fails (its messages are in the error), or leaves an empty output file.
PlotFiles render(const Figure& figure, const std::filesystem::path& stem,
                 const PlotOptions& options = {});

//! Refuses, with an InputError naming `option` and the path, an output path that names no file
//! ("dir/", ".", ".."), holds a control character (a line break would split the script), or
//! whose folder does not exist (it is not created) or cannot take a file (tried, then removed).
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
