#include "piezoshift/psi/surface_figure.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "piezoshift/psi/png_image.hpp"

namespace piezoshift::psi {

io::Figure surface_figure(const Map& surface_nm, double lo_nm, double hi_nm, std::string title) {
  const int side = std::max(surface_nm.width, surface_nm.height);
  const int stride = std::max(1, (side + kMaxSurfaceFigureSide - 1) / kMaxSurfaceFigureSide);
  io::Figure f;
  f.width_px = 640;
  f.height_px = 560;
  io::Panel p;
  p.title =
      stride == 1 ? std::move(title) : fmt::format("{} (every {}th pixel drawn)", title, stride);
  p.x_label = "x [pixel]";
  p.y_label = "y [pixel]";
  p.cb_label = "height [nm]";
  p.key = "off";
  p.equal_axes = true;
  if (std::isfinite(lo_nm) && std::isfinite(hi_nm) && hi_nm > lo_nm)
    p.cb_range = std::pair{lo_nm, hi_nm};
  p.x_range = std::pair{-0.5, surface_nm.width - 0.5};
  p.y_range = std::pair{-0.5, surface_nm.height - 0.5};
  io::Series map;
  map.style = io::SeriesStyle::kImage;
  // Row 0 is the frames' top row: drawn at the top (y counts up from the bottom row), so the map
  // is oriented as the PNG frames it was measured from.
  for (int j = 0; j < surface_nm.height; j += stride) {
    for (int i = 0; i < surface_nm.width; i += stride) {
      map.x.push_back(i);
      map.y.push_back(surface_nm.height - 1 - j);
      map.w.push_back(surface_nm.at(i, j));
    }
  }
  p.series.push_back(std::move(map));
  f.panels.push_back(std::move(p));
  f.caption = "Surface height map in nm; blank: outside the valid pixels.";
  return f;
}

void write_surface_map(const std::filesystem::path& png_path, const Map& surface_nm, double lo_nm,
                       double hi_nm, std::string title) {
  if (io::find_gnuplot()) {
    io::render(surface_figure(surface_nm, lo_nm, hi_nm, std::move(title)), png_path);
    return;
  }
  write_false_colour_png(png_path.string(), surface_nm, lo_nm, hi_nm);
}

}  // namespace piezoshift::psi
