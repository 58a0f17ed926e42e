#pragma once
// A surface map with its lateral scale and units in the HDF5 layout of Zygo's .datx files, as
// prysm's read_zygo_datx (prysm 0.21.1, prysm/io.py) reads it (checked: docs/files.md):
//
//   /Data/Surface/<name>     float64 dataset, rows x columns, row 0 at the top, column 0 at
//                            the left (the .gsf's order); heights in nm; a pixel that holds no
//                            value holds the No Data value. Attributes, each a 1-element array:
//     "Unit"                          "NanoMeters" (prysm reads "NanoMeters" or "Fringes" only)
//     "No Data"                       1.7976931348623157e308: pixels >= it hold no value
//     "Wavelength"                    the instrument's wavelength [m]
//     "Interferometric Scale Factor"  0.5 (reflection; used by readers only for "Fringes")
//     "Obliquity Factor"              1
//     "Title"                         the map's title (a field of our own)
//   /Attributes/<name>       a group whose attributes carry the lateral scale:
//     "Data Context.Data Attributes.Resolution:Value"  metres on the plate per pixel
//     "Data Context.Data Attributes.Resolution:Unit"   "Meters"
//
// The heights are the map's nm doubles themselves, so read_datx gives back what write_datx
// wrote bit for bit (the heights, NaN where no value, the scale, the title). A .datx from
// elsewhere may hold its heights as any float or integer type, in "NanoMeters", "MicroMeters",
// "MilliMeters", "Meters" or "Fringes" (x Obliquity Factor x Interferometric Scale Factor x
// Wavelength), and its resolution in metres, millimetres, micrometres or nanometres.
#include <string>

#include "piezoshift/psi/surface_file.hpp"

namespace piezoshift::psi {

//! Writes s to path (atomically) in the layout above; wavelength_m is the instrument's.
//! std::invalid_argument for an empty map, a scale or wavelength that is not finite and > 0, or
//! a title with a line break or a NUL; core::InputError when the file cannot be written.
void write_datx(const std::string& path, const ScaledSurface& s, double wavelength_m);

//! Reads a .datx. core::InputError naming the file and what is wrong: not a regular file or
//! larger than io::kMaxFrameFileBytes, not HDF5, no /Data/Surface dataset, a dataset that is not
//! 2-D numbers or has more than psi::kMaxFrameSetPixels pixels (refused before it is read), a
//! height unit or resolution it does not know, no lateral resolution; a file on which the HDF5
//! library itself fails (HDF5 1.10 reads some damaged files out of bounds: the file is parsed in
//! a child process, so that is a refusal, not a crash) or takes more than 60 s.
ScaledSurface read_datx(const std::string& path);

}  // namespace piezoshift::psi
