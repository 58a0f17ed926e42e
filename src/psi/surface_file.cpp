#include "piezoshift/psi/surface_file.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/input_file.hpp"

namespace piezoshift::psi {

static_assert(std::endian::native == std::endian::little, "the GSF writer assumes little endian");

namespace {

namespace fs = std::filesystem;

constexpr std::string_view kMagic = "Gwyddion Simple Field 1.0\n";
constexpr std::string_view kMaskKey = "PiezoshiftMask";
// The scale as written: XReal / XRes need not give back the very double XReal was made from.
constexpr std::string_view kScaleKey = "PiezoshiftMetresPerPixel";
constexpr int kMaxSide = 1 << 14;         // pixels: far beyond any camera, bounded before the data
constexpr double kScaleTolerance = 1e-9;  // relative: two scales written from one are equal

// The header, its NUL padding and the data of one field.
std::string gsf_bytes(int width, int height, double m_per_px, std::string_view z_units,
                      const std::string& title, const std::string& extra,
                      const std::vector<float>& values) {
  std::string out(kMagic);
  out += fmt::format("XRes = {}\nYRes = {}\nXReal = {:.17g}\nYReal = {:.17g}\nXYUnits = m\n", width,
                     height, width * m_per_px, height * m_per_px);
  if (!z_units.empty())
    out += fmt::format("ZUnits = {}\n", z_units);
  out += fmt::format("Title = {}\n{} = {:.17g}\n", title, kScaleKey, m_per_px);
  out += extra;
  out.append(4 - out.size() % 4, '\0');  // 1 to 4 NULs: the data starts at a multiple of 4
  const std::size_t at = out.size();
  out.resize(at + values.size() * sizeof(float));
  std::memcpy(out.data() + at, values.data(), values.size() * sizeof(float));
  return out;
}

std::string trimmed(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos)
    return {};
  const auto last = s.find_last_not_of(" \t\r");
  return std::string(s.substr(first, last - first + 1));
}

struct Header {
  std::map<std::string, std::string> fields;
  std::size_t data_start = 0;
};

Header parse_header(const std::string& path, const std::string& data) {
  if (data.compare(0, kMagic.size(), kMagic) != 0)
    throw core::InputError(fmt::format(
        "{}: not a Gwyddion Simple Field file (it must begin with \"Gwyddion Simple Field 1.0\")",
        path));
  const std::size_t nul = data.find('\0', kMagic.size());
  if (nul == std::string::npos)
    throw core::InputError(fmt::format("{}: the header has no end (no NUL byte)", path));
  Header h;
  h.data_start = nul + 4 - nul % 4;
  for (std::size_t i = nul; i < h.data_start && i < data.size(); ++i)
    if (data[i] != '\0')
      throw core::InputError(
          fmt::format("{}: byte {} of the header's padding is not NUL", path, i));
  const std::string_view text(data.data() + kMagic.size(), nul - kMagic.size());
  std::size_t line_no = 1;
  for (std::size_t start = 0; start < text.size(); ++line_no) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos)
      end = text.size();
    const std::string_view line = text.substr(start, end - start);
    start = end + 1;
    if (trimmed(line).empty())
      continue;
    const std::size_t eq = line.find('=');
    if (eq == std::string_view::npos)
      throw core::InputError(fmt::format("{}: header line {}: '{}' is not 'name = value'", path,
                                         line_no + 1, trimmed(line.substr(0, 80))));
    const std::string name = trimmed(line.substr(0, eq));
    if (!h.fields.emplace(name, trimmed(line.substr(eq + 1))).second)
      throw core::InputError(fmt::format("{}: header field {} is given twice", path, name));
  }
  return h;
}

const std::string* field(const Header& h, const std::string& name) {
  const auto it = h.fields.find(name);
  return it == h.fields.end() ? nullptr : &it->second;
}

int pixels(const std::string& path, const Header& h, const char* name) {
  const std::string* v = field(h, name);
  int n = 0;
  if (v == nullptr)
    throw core::InputError(fmt::format("{}: the header has no {} (mandatory)", path, name));
  const auto [end, ec] = std::from_chars(v->data(), v->data() + v->size(), n);
  if (ec != std::errc{} || end != v->data() + v->size() || n < 1 || n > kMaxSide)
    throw core::InputError(
        fmt::format("{}: {} = {}: must be a whole number in 1..{}", path, name, *v, kMaxSide));
  return n;
}

double positive_number(const std::string& path, const Header& h, const char* name) {
  const std::string* v = field(h, name);
  if (v == nullptr)
    throw core::InputError(
        fmt::format("{}: the header has no {} (the lateral scale is needed)", path, name));
  double x = 0.0;
  const auto [end, ec] = std::from_chars(v->data(), v->data() + v->size(), x);
  if (ec != std::errc{} || end != v->data() + v->size() || !std::isfinite(x) || !(x > 0.0))
    throw core::InputError(fmt::format("{}: {} = {}: must be a number > 0", path, name, *v));
  return x;
}

// Metres per unit of a length unit, 0 for anything else.
double metres_per(const std::string& unit) {
  if (unit == "m")
    return 1.0;
  if (unit == "mm")
    return 1e-3;
  if (unit == "um" || unit == "\xC2\xB5m")  // µm in UTF-8
    return 1e-6;
  if (unit == "nm")
    return 1e-9;
  return 0.0;
}

double length_unit(const std::string& path, const Header& h, const char* name) {
  const std::string* v = field(h, name);
  const double f = v == nullptr ? 0.0 : metres_per(*v);
  if (f == 0.0)
    throw core::InputError(fmt::format("{}: {} = {}: must be a length (m, mm, um or nm)", path,
                                       name, v == nullptr ? "(none)" : *v));
  return f;
}

struct Field {
  int width = 0;
  int height = 0;
  double m_per_px = 0.0;
  std::vector<float> values;
  Header header;
};

Field read_field(const std::string& path) {
  const std::string data = io::read_input_file(path, io::kMaxFrameFileBytes);
  Field f;
  f.header = parse_header(path, data);
  f.width = pixels(path, f.header, "XRes");
  f.height = pixels(path, f.header, "YRes");
  const std::size_t n = static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height);
  if (data.size() != f.header.data_start + n * sizeof(float))
    throw core::InputError(fmt::format("{}: {} bytes of data, XRes x YRes = {} x {} needs {}", path,
                                       data.size() - std::min(data.size(), f.header.data_start),
                                       f.width, f.height, n * sizeof(float)));
  const double unit = length_unit(path, f.header, "XYUnits");
  const double mx = positive_number(path, f.header, "XReal") * unit / f.width;
  const double my = positive_number(path, f.header, "YReal") * unit / f.height;
  if (std::fabs(mx - my) > 1e-6 * mx)
    throw core::InputError(
        fmt::format("{}: the pixels are not square ({:.6g} m across, {:.6g} m down): only square "
                    "pixels are read",
                    path, mx, my));
  f.m_per_px = mx;
  if (field(f.header, std::string(kScaleKey)) != nullptr) {
    const double written = positive_number(path, f.header, std::string(kScaleKey).c_str());
    if (std::fabs(written - mx) > 1e-9 * mx)
      throw core::InputError(fmt::format("{}: {} = {:.17g} is not XReal / XRes = {:.17g} m", path,
                                         kScaleKey, written, mx));
    f.m_per_px = written;
  }
  f.values.resize(n);
  std::memcpy(f.values.data(), data.data() + f.header.data_start, n * sizeof(float));
  return f;
}

// The valid pixels named by the surface's PiezoshiftMask field: a plain file name beside it.
void apply_mask(const std::string& path, const Field& surface, const std::string& name,
                ScaledSurface& s) {
  if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
    throw core::InputError(
        fmt::format("{}: {} = {}: must be the name of a file beside it", path, kMaskKey, name));
  const std::string mask_path = (fs::path(path).parent_path() / name).string();
  const Field m = read_field(mask_path);
  if (m.width != surface.width || m.height != surface.height ||
      std::fabs(m.m_per_px - surface.m_per_px) > kScaleTolerance * surface.m_per_px)
    throw core::InputError(fmt::format(
        "{}: the mask is {} x {} pixels of {:.9g} m, its surface {} ({} x {} of {:.9g} m)",
        mask_path, m.width, m.height, m.m_per_px, path, surface.width, surface.height,
        surface.m_per_px));
  for (std::size_t p = 0; p < m.values.size(); ++p) {
    if (m.values[p] == 0.0f)
      s.height_nm.v[p] = std::numeric_limits<double>::quiet_NaN();
    else if (m.values[p] != 1.0f)
      throw core::InputError(fmt::format("{}: pixel ({}, {}) is {}: a mask holds 0 or 1", mask_path,
                                         p % m.width, p / m.width, m.values[p]));
  }
}

}  // namespace

std::string gsf_mask_path(const std::string& path) {
  const fs::path p(path);
  return (p.parent_path() / (p.stem().string() + "_mask" + p.extension().string())).string();
}

void write_gsf(const std::string& path, const ScaledSurface& s) {
  const Map& m = s.height_nm;
  if (m.width < 1 || m.height < 1 || m.size() != static_cast<std::size_t>(m.width) * m.height)
    throw std::invalid_argument("write_gsf: an empty map");
  if (!std::isfinite(s.m_per_px) || !(s.m_per_px > 0.0))
    throw std::invalid_argument("write_gsf: the lateral scale must be finite and > 0");
  if (s.title.find_first_of(std::string_view("\n\r\0", 3)) != std::string::npos)
    throw std::invalid_argument("write_gsf: the title must be one line without NUL");
  std::vector<float> heights(m.size());
  std::vector<float> valid(m.size());
  bool all_valid = true;
  for (std::size_t p = 0; p < m.size(); ++p) {
    const bool ok = std::isfinite(m.v[p]);
    heights[p] = ok ? static_cast<float>(m.v[p] * 1e-9) : 0.0f;
    valid[p] = ok ? 1.0f : 0.0f;
    all_valid = all_valid && ok;
  }
  std::string extra;
  if (!all_valid) {
    const std::string mask_path = gsf_mask_path(path);
    extra = fmt::format("{} = {}\n", kMaskKey, fs::path(mask_path).filename().string());
    io::write_file_atomically(mask_path, gsf_bytes(m.width, m.height, s.m_per_px, "",
                                                   "valid pixels of " + s.title, "", valid));
  }
  io::write_file_atomically(path,
                            gsf_bytes(m.width, m.height, s.m_per_px, "m", s.title, extra, heights));
}

ScaledSurface read_gsf(const std::string& path) {
  const Field f = read_field(path);
  const double nm_per_unit = length_unit(path, f.header, "ZUnits") * 1e9;
  ScaledSurface s;
  s.m_per_px = f.m_per_px;
  s.height_nm = Map(f.width, f.height);
  for (std::size_t p = 0; p < f.values.size(); ++p)
    s.height_nm.v[p] = std::isfinite(f.values[p]) ? f.values[p] * nm_per_unit
                                                  : std::numeric_limits<double>::quiet_NaN();
  if (const std::string* t = field(f.header, "Title"))
    s.title = *t;
  if (const std::string* mask = field(f.header, std::string(kMaskKey)))
    apply_mask(path, f, *mask, s);
  return s;
}

}  // namespace piezoshift::psi
