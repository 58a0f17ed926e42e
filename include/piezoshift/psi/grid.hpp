#pragma once
// Images on the camera's pixel grid: a Map (one double per pixel: intensity, phase or height), a
// Mask (the pupil: pixels that hold data) and the Pupil they define.
//
// Pixel (i, j) is column i, row j (row 0 at the top), stored row-major at j * width + i.
// Pupil coordinates, used by the Zernike fit and by the tilt-aware algorithms:
//   x = (i - cx) / R,   y = (cy - j) / R     (y up, so x, y, z are right-handed)
// with (cx, cy) the centroid of the mask and R the largest distance of a mask pixel from it, so
// the pupil is the unit disk for a circular mask.
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace piezoshift::psi {

struct Map {
  int width = 0;
  int height = 0;
  std::vector<double> v;  //!< row-major, width * height

  Map() = default;
  Map(int w, int h, double fill = 0.0)
      : width(w), height(h), v(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}
  std::size_t size() const { return v.size(); }
  double& at(int i, int j) { return v[static_cast<std::size_t>(j) * width + i]; }
  double at(int i, int j) const { return v[static_cast<std::size_t>(j) * width + i]; }
};

struct Mask {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> v;  //!< 1: inside the pupil

  Mask() = default;
  Mask(int w, int h, std::uint8_t fill = 1)
      : width(w), height(h), v(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}
  std::size_t size() const { return v.size(); }
  std::size_t count() const;
};

//! The centred disk of radius_px (pixels whose centre lies within radius_px of the grid's centre).
Mask disk_mask(int width, int height, double radius_px);

struct Pupil {
  double cx = 0.0;  //!< centroid [px]
  double cy = 0.0;
  double radius_px = 1.0;  //!< R, largest distance of a mask pixel from the centroid [px]
  double x(int i) const { return (i - cx) / radius_px; }
  double y(int j) const { return (cy - j) / radius_px; }
};

//! The smallest and largest finite value of a map (its colour scale); {0, 0} when none is finite.
std::pair<double, double> finite_range(const Map& map);

//! The pupil of a mask. Throws std::invalid_argument for an empty mask.
Pupil pupil_of(const Mask& mask);

}  // namespace piezoshift::psi
