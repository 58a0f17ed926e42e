#include "piezoshift/psi/npy.hpp"

#include <bit>
#include <cstring>
#include <regex>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/input_file.hpp"

namespace piezoshift::psi {

static_assert(std::endian::native == std::endian::little, "npy writer assumes little endian");

void write_npy(const std::string& path, const Map& map) {
  std::string header = fmt::format(
      "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {}), }}", map.height, map.width);
  const std::size_t preamble = 10;  // magic (6) + version (2) + header length (2)
  std::size_t total = preamble + header.size() + 1;
  total = (total + 127) / 128 * 128;
  header.append(total - preamble - header.size() - 1, ' ');
  header.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  const auto len = static_cast<std::uint16_t>(header.size());
  out.push_back(static_cast<char>(len & 0xff));
  out.push_back(static_cast<char>(len >> 8));
  out += header;
  const std::size_t bytes = map.v.size() * sizeof(double);
  const std::size_t at = out.size();
  out.resize(at + bytes);
  if (bytes > 0)
    std::memcpy(out.data() + at, map.v.data(), bytes);
  io::write_file_atomically(path, out);
}

Map read_npy(const std::string& path) {
  const std::string data = io::read_input_file(path, io::kMaxFrameFileBytes);
  if (data.size() < 10 || data.compare(0, 6, "\x93NUMPY") != 0)
    throw core::InputError(fmt::format("{}: not a .npy file", path));
  if (data[6] != 1)
    throw core::InputError(
        fmt::format("{}: .npy version {} (only 1.0 is read)", path, static_cast<int>(data[6])));
  const std::size_t len = static_cast<unsigned char>(data[8]) |
                          (static_cast<std::size_t>(static_cast<unsigned char>(data[9])) << 8);
  if (data.size() < 10 + len)
    throw core::InputError(fmt::format("{}: truncated header", path));
  const std::string header = data.substr(10, len);
  if (header.find("'descr': '<f8'") == std::string::npos ||
      header.find("'fortran_order': False") == std::string::npos)
    throw core::InputError(fmt::format("{}: only little-endian float64 in C order is read", path));
  std::smatch m;
  const std::regex shape2(R"('shape': \((\d+), (\d+)\))"), shape1(R"('shape': \((\d+),\))");
  Map map;
  if (std::regex_search(header, m, shape2)) {
    map = Map(std::stoi(m[2].str()), std::stoi(m[1].str()));
  } else if (std::regex_search(header, m, shape1)) {
    map = Map(std::stoi(m[1].str()), 1);
  } else {
    throw core::InputError(fmt::format("{}: only 1-D or 2-D arrays are read", path));
  }
  const std::size_t bytes = map.v.size() * sizeof(double);
  if (data.size() != 10 + len + bytes)
    throw core::InputError(
        fmt::format("{}: {} data bytes, expected {}", path, data.size() - 10 - len, bytes));
  if (bytes > 0)
    std::memcpy(map.v.data(), data.data() + 10 + len, bytes);
  return map;
}

}  // namespace piezoshift::psi
