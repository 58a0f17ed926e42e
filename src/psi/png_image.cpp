#include "piezoshift/psi/png_image.hpp"

#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/input_file.hpp"

namespace piezoshift::psi {
namespace {

// libpng reports errors through a callback that must not return; we throw (libpng is built with
// unwind tables on Debian) and catch at the top of each function, where the structs are freed.
struct PngFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

[[noreturn]] void on_error(png_structp, png_const_charp msg) {
  throw PngFailure(msg);
}
void on_warning(png_structp, png_const_charp) {}

struct Reader {
  const std::string* data;
  std::size_t at;
};

void read_from_memory(png_structp png, png_bytep out, png_size_t n) {
  auto* r = static_cast<Reader*>(png_get_io_ptr(png));
  if (r->at + n > r->data->size())
    png_error(png, "unexpected end of file");
  std::memcpy(out, r->data->data() + r->at, n);
  r->at += n;
}

void write_to_memory(png_structp png, png_bytep in, png_size_t n) {
  auto* s = static_cast<std::string*>(png_get_io_ptr(png));
  s->append(reinterpret_cast<const char*>(in), n);
}
void flush_nothing(png_structp) {}

// Rows (already in the PNG's byte order: 8-bit, or 16-bit big-endian) as a PNG file's bytes;
// what names it in messages.
std::string encode_png(const std::string& what, int width, int height, int bit_depth,
                       int color_type, const std::vector<std::vector<png_byte>>& rows) {
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw core::InputError(fmt::format("{}: libpng could not start", what));
  }
  try {
    png_set_write_fn(png, &out, write_to_memory, flush_nothing);
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height),
                 bit_depth, color_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (const auto& row : rows)
      png_write_row(png, row.data());
    png_write_end(png, nullptr);
  } catch (const PngFailure& e) {
    png_destroy_write_struct(&png, &info);
    throw core::InputError(fmt::format("{}: {}", what, e.what()));
  }
  png_destroy_write_struct(&png, &info);
  return out;
}

void write_png(const std::string& path, int width, int height, int bit_depth, int color_type,
               const std::vector<std::vector<png_byte>>& rows) {
  io::write_file_atomically(path, encode_png(path, width, height, bit_depth, color_type, rows));
}

// Blue (lo) - white - red (hi).
std::array<png_byte, 3> colour(double t) {
  t = std::clamp(t, 0.0, 1.0);
  auto b = [](double v) {
    return static_cast<png_byte>(std::lround(255.0 * std::clamp(v, 0.0, 1.0)));
  };
  if (t < 0.5) {
    const double u = t / 0.5;
    return {b(0.15 + 0.85 * u), b(0.3 + 0.7 * u), b(1.0)};
  }
  const double u = (t - 0.5) / 0.5;
  return {b(1.0), b(1.0 - 0.8 * u), b(1.0 - 0.85 * u)};
}

}  // namespace

GrayImage read_png_gray(const std::string& path) {
  const std::string data = io::read_input_file(path, io::kMaxDataFileBytes);
  if (data.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(data.data()), 0, 8) != 0)
    throw core::InputError(fmt::format("{}: not a PNG file", path));
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw core::InputError(fmt::format("{}: libpng could not start", path));
  }
  Reader reader{&data, 0};
  GrayImage img;
  try {
    png_set_read_fn(png, &reader, read_from_memory);
    png_read_info(png, info);
    const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
    if (w < 1 || h < 1 || w > kMaxPngSide || h > kMaxPngSide)
      throw PngFailure(fmt::format("{} x {} pixels (1 to {} on each side)", w, h, kMaxPngSide));
    const int type = png_get_color_type(png, info);
    png_set_expand(png);  // palette to RGB, gray 1/2/4 bits to 8, tRNS to alpha
    png_set_strip_alpha(png);
    if (type & PNG_COLOR_MASK_COLOR)
      png_set_rgb_to_gray_fixed(png, 1, -1, -1);
    // An Adam7 file's rows come in seven passes, each filling part of every row: libpng merges
    // them when asked and each pass's rows are read over the same whole-image buffer.
    const int passes = png_set_interlace_handling(png);
    png_read_update_info(png, info);
    const int depth = png_get_bit_depth(png, info);
    const int channels = png_get_channels(png, info);
    if (channels != 1 || (depth != 8 && depth != 16))
      throw PngFailure(fmt::format("unsupported layout ({} channels, {} bits)", channels, depth));
    img.bit_depth = depth;
    img.counts = Map(static_cast<int>(w), static_cast<int>(h));
    const std::size_t row_bytes = png_get_rowbytes(png, info);
    std::vector<png_byte> pixels(row_bytes * h);
    for (int pass = 0; pass < passes; ++pass)
      for (png_uint_32 j = 0; j < h; ++j)
        png_read_row(png, pixels.data() + j * row_bytes, nullptr);
    for (png_uint_32 j = 0; j < h; ++j) {
      const png_byte* row = pixels.data() + j * row_bytes;
      for (png_uint_32 i = 0; i < w; ++i)
        img.counts.v[j * w + i] =
            depth == 8 ? row[i] : static_cast<double>((row[2 * i] << 8) | row[2 * i + 1]);
    }
  } catch (const PngFailure& e) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw core::InputError(fmt::format("{}: {}", path, e.what()));
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return img;
}

std::string encode_png_gray16(const Map& counts) {
  std::vector<std::vector<png_byte>> rows(static_cast<std::size_t>(counts.height));
  for (int j = 0; j < counts.height; ++j) {
    auto& row = rows[static_cast<std::size_t>(j)];
    row.resize(2 * static_cast<std::size_t>(counts.width));
    for (int i = 0; i < counts.width; ++i) {
      const double v = counts.at(i, j);
      const auto c =
          static_cast<unsigned>(std::isfinite(v) ? std::clamp(std::lround(v), 0L, 65535L) : 0L);
      row[2 * static_cast<std::size_t>(i)] = static_cast<png_byte>(c >> 8);
      row[2 * static_cast<std::size_t>(i) + 1] = static_cast<png_byte>(c & 0xff);
    }
  }
  return encode_png("16-bit gray PNG", counts.width, counts.height, 16, PNG_COLOR_TYPE_GRAY, rows);
}

void write_png_gray16(const std::string& path, const Map& counts) {
  io::write_file_atomically(path, encode_png_gray16(counts));
}

void write_mask_png(const std::string& path, const Mask& mask) {
  std::vector<std::vector<png_byte>> rows(static_cast<std::size_t>(mask.height));
  for (int j = 0; j < mask.height; ++j)
    for (int i = 0; i < mask.width; ++i)
      rows[static_cast<std::size_t>(j)].push_back(
          mask.v[static_cast<std::size_t>(j) * mask.width + i] ? 255 : 0);
  write_png(path, mask.width, mask.height, 8, PNG_COLOR_TYPE_GRAY, rows);
}

Mask read_mask_png(const std::string& path) {
  const GrayImage g = read_png_gray(path);
  Mask m(g.counts.width, g.counts.height, 0);
  for (std::size_t p = 0; p < m.size(); ++p)
    m.v[p] = g.counts.v[p] > 0.0 ? 1 : 0;
  if (m.count() == 0)
    throw core::InputError(fmt::format("{}: the mask is empty (no nonzero pixel)", path));
  return m;
}

Mask read_mask_of_size(const std::string& path, int width_px, int height_px, std::string_view of) {
  Mask m = read_mask_png(path);
  if (m.width != width_px || m.height != height_px)
    throw core::InputError(fmt::format("{}: mask is {} x {} pixels, {} {} x {}", path, m.width,
                                       m.height, of, width_px, height_px));
  return m;
}

std::string encode_false_colour_png(const Map& map, double lo, double hi) {
  const int bar = std::max(12, map.width / 16), gap = std::max(4, map.width / 64);
  const int w = map.width + gap + bar, h = map.height;
  const double span = hi > lo ? hi - lo : 1.0;
  std::vector<std::vector<png_byte>> rows(
      static_cast<std::size_t>(h), std::vector<png_byte>(3 * static_cast<std::size_t>(w), 255));
  for (int j = 0; j < h; ++j) {
    auto& row = rows[static_cast<std::size_t>(j)];
    auto put = [&row](int i, std::array<png_byte, 3> c) {
      std::copy(c.begin(), c.end(), row.begin() + 3 * static_cast<std::ptrdiff_t>(i));
    };
    for (int i = 0; i < map.width; ++i) {
      const double v = map.at(i, j);
      put(i, std::isfinite(v) ? colour((v - lo) / span) : std::array<png_byte, 3>{128, 128, 128});
    }
    // scale bar: hi at the top, lo at the bottom, black ticks at 0, 1/4, ... 1
    const double t = h > 1 ? 1.0 - static_cast<double>(j) / (h - 1) : 0.5;
    const bool tick = std::fabs(t * 4.0 - std::round(t * 4.0)) * (h - 1) / 4.0 < 0.5;
    for (int i = map.width + gap; i < w; ++i)
      put(i, tick && i < map.width + gap + bar / 3 ? std::array<png_byte, 3>{0, 0, 0} : colour(t));
  }
  return encode_png("false-colour PNG", w, h, 8, PNG_COLOR_TYPE_RGB, rows);
}

void write_false_colour_png(const std::string& path, const Map& map, double lo, double hi) {
  io::write_file_atomically(path, encode_false_colour_png(map, lo, hi));
}

}  // namespace piezoshift::psi
