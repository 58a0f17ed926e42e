#pragma once
// The options `psi analyze`, `psi calibrate` and `measure` share: lists of numbers, the pupil's
// mask, the algorithm and its frame count, the wavelength.
#include <cstddef>
#include <string>
#include <vector>

#include "piezoshift/psi/grid.hpp"
#include "piezoshift/psi/phase_algorithms.hpp"

namespace piezoshift::app {

//! "0,1.5,3.1" as numbers; InputError naming option and the item that is not one.
std::vector<double> parse_list(const std::string& text, const std::string& option);
//! The mask PNG at path, of the frame's size; every pixel when path is empty.
psi::Mask load_mask(const std::string& path, const psi::Map& frame);
//! The named algorithm, or the one made for that many frames (lsq for other counts).
psi::Algorithm choose_algorithm(const std::string& name, std::size_t frames);
//! InputError when the algorithm needs another frame count.
void check_count(psi::Algorithm a, std::size_t frames);
//! InputError outside 100..20000 nm.
void check_wavelength(double nm);

}  // namespace piezoshift::app
