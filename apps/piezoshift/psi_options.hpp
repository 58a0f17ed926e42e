#pragma once
// The options `psi analyze`, `psi calibrate` and `measure` share: lists of numbers, the pupil's
// mask, the algorithm and its frame count, the wavelength.
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "piezoshift/psi/grid.hpp"
#include "piezoshift/psi/phase_algorithms.hpp"
#include "piezoshift/psi/png_image.hpp"

namespace piezoshift::app {

//! The mask PNG at path, of a size (psi/png_image.hpp).
using psi::read_mask_of_size;
//! "0,1.5,3.1" as numbers; InputError naming option and the item that is not one.
std::vector<double> parse_list(const std::string& text, const std::string& option);
//! The pupil: the mask PNG at path (of the frames' size), else found from the frames' fringe
//! modulation (psi/pupil_detection.hpp; InputError prefixed by who when it cannot be), with what
//! the JSON reports of it.
struct PupilChoice {
  psi::Mask mask;
  nlohmann::ordered_json json;
};
PupilChoice choose_pupil(const std::string& path, std::span<const psi::Map> frames,
                         const std::string& who);
//! The named algorithm, or the one made for that many frames (lsq for other counts).
psi::Algorithm choose_algorithm(const std::string& name, std::size_t frames);
//! InputError when the algorithm needs another frame count.
void check_count(psi::Algorithm a, std::size_t frames);
//! InputError outside 100..20000 nm.
void check_wavelength(double nm);

}  // namespace piezoshift::app
