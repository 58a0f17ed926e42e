#pragma once
// Frames, masks and false-colour maps as PNG files, through Debian's libpng (libpng-dev).
//   read_png_gray: 8- or 16-bit grayscale (colour images are converted to gray by libpng's
//     rgb_to_gray, alpha stripped); values returned as counts 0..2^bits - 1, sizes up to
//     kMaxPngSide on each side.
//   write_png_gray16: counts rounded and clipped to 0..65535.
//   write_mask_png / read_mask: 8-bit, nonzero = inside the pupil.
//   write_false_colour_png: a height map drawn with a blue-white-red scale, NaN as gray, and a
//     scale bar (colour ramp with tick marks every quarter of the range) on the right; the range
//     is printed by the caller (the PNG holds no text).
//   encode_*: the same images as a PNG file's bytes, for a caller that sends them (the dashboard).
// Set-up only; every error is core::InputError naming the file.
#include <string>
#include <string_view>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

inline constexpr int kMaxPngSide = 2048;

struct GrayImage {
  Map counts;         //!< pixel values 0 .. 2^bit_depth - 1
  int bit_depth = 8;  //!< 8 or 16
};

GrayImage read_png_gray(const std::string& path);
void write_png_gray16(const std::string& path, const Map& counts);
std::string encode_png_gray16(const Map& counts);
void write_mask_png(const std::string& path, const Mask& mask);
Mask read_mask_png(const std::string& path);
//! read_mask_png of a mask that must be width_px x height_px: core::InputError naming path and
//! `of` (what it must match: "the frames") when it is not.
Mask read_mask_of_size(const std::string& path, int width_px, int height_px, std::string_view of);
//! Writes the map with the colour scale spanning [lo, hi]; returns nothing, throws on I/O.
void write_false_colour_png(const std::string& path, const Map& map, double lo, double hi);
std::string encode_false_colour_png(const Map& map, double lo, double hi);

}  // namespace piezoshift::psi
