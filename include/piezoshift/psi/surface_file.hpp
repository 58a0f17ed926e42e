#pragma once
// A surface map with its lateral scale and units, in Gwyddion Simple Field (.gsf), the format of
// gwyddion.net's user guide ("Simple Field Files"), which Gwyddion opens (checked: docs/files.md),
// as do readers written to that specification:
//
//   "Gwyddion Simple Field 1.0\n"
//   "XRes = 256\n" "YRes = 256\n"            pixels, mandatory
//   "XReal = 0.0533\n" "YReal = 0.0533\n"    the field's size in XYUnits
//   "XYUnits = m\n" "ZUnits = m\n"           base SI units
//   "Title = ...\n"
//   "PiezoshiftMetresPerPixel = ...\n"      the scale to 17 digits (XReal / XRes, as written)
//   1 to 4 NUL bytes, so that the data starts at a multiple of 4 bytes
//   XRes * YRes little-endian IEEE float32, row by row from the top, each from the left
//
// Heights are written in metres (the map's nm x 1e-9, rounded to float32); the lateral scale is
// metres on the plate per pixel (square pixels). GSF has no invalid value, so a pixel that holds
// none (NaN in the map: outside the pupil, or without modulation) is written as 0 m, and the
// valid pixels go into a second GSF beside it (1 valid, 0 not; the same size and scale), which
// the surface's header names as `PiezoshiftMask = NAME` (a header field of our own, which the
// format allows and Gwyddion lists as metadata). read_gsf reads it back: what write_gsf wrote
// comes back bit for bit (the float32 heights, the mask, the scale, the title). A GSF from
// elsewhere, without that field, has every finite pixel valid; XYUnits and ZUnits may then be
// m, mm, um (or µm) or nm.
#include <string>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

struct ScaledSurface {
  Map height_nm;        //!< NaN where the pixel holds no value
  double m_per_px = 0;  //!< metres on the plate per pixel, both directions
  std::string title;    //!< one line, no NUL
};

//! "surface_m.gsf" -> "surface_m_mask.gsf": the name of the valid pixels' file beside a surface.
std::string gsf_mask_path(const std::string& path);

//! Writes s to path (and, when a pixel holds no value, its mask to gsf_mask_path(path)),
//! atomically. std::invalid_argument for an empty map, a scale that is not finite and > 0, or a
//! title with a line break or a NUL.
void write_gsf(const std::string& path, const ScaledSurface& s);

//! Reads a GSF (and the mask it names). core::InputError naming the file and what is wrong: not
//! a GSF, a missing or bad XRes/YRes, a size that does not match the data, units that are not a
//! length, pixels that are not square, a mask that does not match.
ScaledSurface read_gsf(const std::string& path);

}  // namespace piezoshift::psi
