// `piezoshift psi compare A.gsf B.datx`: a map measured elsewhere against ours, pixel for pixel
// (docs/psi.md). Each is read as a Gwyddion Simple Field (.gsf) or Zygo .datx file with its
// lateral scale; maps of different sizes or scales are refused, naming which; an unreadable file
// exits 2 naming it.
#include "psi_compare.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <tuple>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/psi/surface_comparison.hpp"
#include "piezoshift/psi/surface_datx.hpp"
#include "piezoshift/psi/surface_file.hpp"

namespace piezoshift::app {
namespace {

using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

constexpr int kZernikeTerms = 37;
constexpr double kScaleTolerance = 1e-6;  // relative: a scale written as 17 digits reads back equal

psi::ScaledSurface read_surface(const std::string& path) {
  const fs::path extension = fs::path(path).extension();
  if (extension == ".gsf")
    return psi::read_gsf(path);
  if (extension == ".datx")
    return psi::read_datx(path);
  throw core::InputError(
      fmt::format("{}: only Gwyddion Simple Field (.gsf) and Zygo .datx files are compared", path));
}

// A GSF title is one line: a file name's line breaks and NULs become spaces.
std::string one_line(std::string s) {
  std::replace_if(
      s.begin(), s.end(), [](char ch) { return ch == '\n' || ch == '\r' || ch == '\0'; }, ' ');
  return s;
}

std::size_t valid_pixels(const psi::Map& m) {
  return static_cast<std::size_t>(
      std::count_if(m.v.begin(), m.v.end(), [](double v) { return std::isfinite(v); }));
}

Json describe(const std::string& path, const psi::ScaledSurface& s) {
  return Json{{"file", path},
              {"title", s.title},
              {"width_px", s.height_nm.width},
              {"height_px", s.height_nm.height},
              {"m_per_px", s.m_per_px},
              {"valid_pixels", valid_pixels(s.height_nm)}};
}

void print_comparison(const PsiCompareOptions& o, const psi::ScaledSurface& a,
                      const psi::ScaledSurface& b, const psi::SurfaceComparison& c) {
  for (const auto& [name, s, file] : {std::tuple{"A", &a, &o.a}, std::tuple{"B", &b, &o.b}})
    fmt::print("{}: {}  {} x {} px of {:.6g} mm, {} valid pixels\n", name, *file,
               s->height_nm.width, s->height_nm.height, 1e3 * s->m_per_px,
               valid_pixels(s->height_nm));
  fmt::print(
      "B - A over {} pixels valid in both: RMS {:.3f} nm (piston removed), {:.3f} nm "
      "(piston and tilt removed), PV {:.3f} nm\n",
      c.pixels, c.rms_nm, c.rms_tilt_removed_nm, c.pv_nm);
  fmt::print(
      "Zernike (Noll, nm RMS, over those pixels):\n     j          A          B      B - A\n");
  for (std::size_t j = 0; j < c.zernike_difference_nm.size(); ++j)
    fmt::print("  {:4}  {:9.3f}  {:9.3f}  {:9.3f}\n", j + 1, c.zernike_a_nm[j], c.zernike_b_nm[j],
               c.zernike_difference_nm[j]);
  if (!o.out.empty())
    fmt::print("written: {0}/difference_m.gsf {0}/comparison.json\n", o.out);
}

}  // namespace

int run_psi_compare(const PsiCompareOptions& o) {
  const psi::ScaledSurface a = read_surface(o.a);
  const psi::ScaledSurface b = read_surface(o.b);
  if (a.height_nm.width != b.height_nm.width || a.height_nm.height != b.height_nm.height)
    throw core::InputError(fmt::format(
        "psi compare: the maps' sizes differ: {} is {} x {} pixels, {} is {} x {}", o.a,
        a.height_nm.width, a.height_nm.height, o.b, b.height_nm.width, b.height_nm.height));
  if (std::fabs(a.m_per_px - b.m_per_px) > kScaleTolerance * a.m_per_px)
    throw core::InputError(fmt::format(
        "psi compare: the maps' lateral scales differ: {} has {:.9g} m per pixel, {} {:.9g}", o.a,
        a.m_per_px, o.b, b.m_per_px));
  work_begins();  // the difference and three Zernike fits
  psi::SurfaceComparison c;
  try {
    c = psi::compare_surfaces(a.height_nm, b.height_nm, kZernikeTerms);
  } catch (const std::invalid_argument& e) {
    throw core::InputError(fmt::format("psi compare {} {}: {}", o.a, o.b, e.what()));
  }
  const Json j{
      {"a", describe(o.a, a)},          {"b", describe(o.b, b)},
      {"common_pixels", c.pixels},      {"difference", "b - a"},
      {"difference_rms_nm", c.rms_nm},  {"difference_rms_tilt_removed_nm", c.rms_tilt_removed_nm},
      {"difference_pv_nm", c.pv_nm},    {"zernike_a_nm", c.zernike_a_nm},
      {"zernike_b_nm", c.zernike_b_nm}, {"zernike_difference_nm", c.zernike_difference_nm}};
  if (!o.out.empty()) {
    fs::create_directories(o.out);
    psi::write_gsf((fs::path(o.out) / "difference_m.gsf").string(),
                   {c.difference_nm, a.m_per_px, one_line(fmt::format("{} - {}", o.b, o.a))});
    io::write_file_atomically((fs::path(o.out) / "comparison.json").string(), j.dump(2) + "\n");
  }
  if (o.json)
    fmt::print("{}\n", j.dump(2));
  else
    print_comparison(o, a, b, c);
  return 0;
}

}  // namespace piezoshift::app
