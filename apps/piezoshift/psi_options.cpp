#include "psi_options.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/psi/png_image.hpp"
#include "piezoshift/psi/pupil_detection.hpp"

namespace piezoshift::app {

std::vector<double> parse_list(const std::string& text, const std::string& option) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      const double x = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(x))
        throw std::invalid_argument(item);
      v.push_back(x);
    } catch (const std::exception&) {
      throw core::InputError(fmt::format("{} '{}': '{}' is not a number", option, text, item));
    }
  }
  return v;
}

// The pupil: the mask file given, else found from the frames' fringe modulation
// (pupil_detection.hpp), with what the JSON reports of it. who prefixes a refusal.
PupilChoice choose_pupil(const std::string& path, std::span<const psi::Map> frames,
                         const std::string& who) {
  const psi::Map& frame = frames.front();
  PupilChoice c;
  if (!path.empty()) {
    c.mask = read_mask_of_size(path, frame.width, frame.height, "the frames");
    c.json = {{"source", "mask"}, {"file", path}};
  } else {
    psi::DetectedPupil d;
    try {
      d = psi::pupil_from_modulation(frames);
    } catch (const std::invalid_argument& e) {
      throw core::InputError(fmt::format("{}: {}", who, e.what()));
    }
    c.mask = std::move(d.mask);
    c.json = {
        {"source", "modulation"}, {"modulation_max", d.modulation_max}, {"threshold", d.threshold}};
  }
  c.json["pixels"] = c.mask.count();
  if (c.mask.count() > 0) {
    const psi::Pupil p = psi::pupil_of(c.mask);
    c.json["centre_px"] = {p.cx, p.cy};
    c.json["radius_px"] = p.radius_px;
  }
  return c;
}

psi::Algorithm choose_algorithm(const std::string& name, std::size_t frames) {
  if (!name.empty())
    return psi::parse_algorithm(name);
  switch (frames) {
    case 4:
      return psi::Algorithm::kFourStep;
    case 5:
      return psi::Algorithm::kHariharan5;
    case 7:
      return psi::Algorithm::kDeGroot7;
    case 13:
      return psi::Algorithm::kFrame13;
    default:
      return psi::Algorithm::kLeastSquares;
  }
}

void check_count(psi::Algorithm a, std::size_t frames) {
  const int need = psi::required_frames(a);
  if (need > 0 && static_cast<std::size_t>(need) != frames)
    throw core::InputError(fmt::format("--algorithm {} needs {} frames, {} given",
                                       psi::algorithm_name(a), need, frames));
}

void check_wavelength(double nm) {
  if (!(nm >= 100.0 && nm <= 20000.0))
    throw core::InputError(fmt::format("--wavelength-nm {}: must be in 100..20000", nm));
}

}  // namespace piezoshift::app
