#pragma once
// numpy .npy files, format version 1.0 (numpy's NEP 1 / numpy.lib.format): the magic
// "\x93NUMPY", version 1 0, a little-endian uint16 header length, then an ASCII dict
//   {'descr': '<f8', 'fortran_order': False, 'shape': (height, width), }
// padded with spaces and ended by '\n' so that magic + length + header is a multiple of 64
// bytes (we pad to 128, which numpy also reads), then the raw little-endian float64 data in C
// order. Only what piezoshift writes is read back: 1-D or 2-D '<f8', C order.
#include <string>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

//! Writes map as a (height, width) float64 array, atomically. Throws core::InputError naming path.
void write_npy(const std::string& path, const Map& map);

//! Reads a 2-D (or 1-D, as one row) '<f8' C-order array. Throws core::InputError naming path.
Map read_npy(const std::string& path);

}  // namespace piezoshift::psi
