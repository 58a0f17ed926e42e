#include "piezoshift/psi/zernike_figure.hpp"

namespace piezoshift::psi {

io::Figure zernike_figure(std::span<const double> zernike_nm) {
  io::Figure f;
  f.width_px = 800;
  f.height_px = 440;
  io::Panel p;
  p.title =
      "Zernike coefficients, piston and tilt removed (j = 4 defocus, 5-6 astigmatism, 7-8 coma, 11 "
      "spherical)";
  p.x_label = "Noll index j";
  p.y_label = "coefficient, RMS [nm]";
  p.key = "off";
  io::Series bars;
  bars.style = io::SeriesStyle::kBoxes;
  for (std::size_t k = 3; k < zernike_nm.size(); ++k) {
    bars.x.push_back(static_cast<double>(k + 1));
    bars.y.push_back(zernike_nm[k]);
    bars.w.push_back(0.7);
  }
  p.series.push_back(std::move(bars));
  f.panels.push_back(std::move(p));
  f.caption = "Zernike coefficients of the measured surface (Noll j ≥ 4), RMS-normalised in nm.";
  return f;
}

}  // namespace piezoshift::psi
