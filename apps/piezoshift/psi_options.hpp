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

namespace piezoshift::app {

//! The mask PNG at path; InputError naming it when it is not width_px x height_px (`of`: what
//! must have that size, "the frames", "the camera's frames").
psi::Mask read_mask_of_size(const std::string& path, int width_px, int height_px,
                            std::string_view of);
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
