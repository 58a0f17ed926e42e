#include "piezoshift/psi/surface_datx.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstring>

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/input_file.hpp"
#include "piezoshift/psi/frame_set.hpp"

namespace piezoshift::psi {

namespace {

namespace fs = std::filesystem;

// Zygo's own names, as prysm's read_zygo_datx looks them up.
constexpr const char* kSurfaceGroup = "/Data/Surface";
constexpr const char* kAttributesGroup = "/Attributes";
constexpr const char* kResolutionValue = "Data Context.Data Attributes.Resolution:Value";
constexpr const char* kResolutionUnit = "Data Context.Data Attributes.Resolution:Unit";
constexpr const char* kOurName = "Piezoshift";  // the one child of each group above
constexpr double kNoData = std::numeric_limits<double>::max();
constexpr double kScaleFactor = 0.5;  // reflection: a fringe is half a wavelength of height
constexpr int kMaxSide = 1 << 14;     // pixels, as the .gsf reader
constexpr hsize_t kMaxAttributeValues = 1 << 16;

// An HDF5 identifier closed when it goes out of scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle& operator=(Handle&&) = delete;
  ~Handle() {
    if (id_ >= 0)
      close_(id_);
  }
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// HDF5 prints its error stack to stderr by default; failures become InputError instead.
void silence_hdf5() {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

// ---------------------------------------------------------------------------------- writing

class Writer {
 public:
  explicit Writer(const std::string& path) : path_(path) {}

  void check(bool ok, std::string_view what) const {
    if (!ok)
      throw core::InputError(fmt::format("{}: HDF5 could not write {}", path_, what));
  }
  Handle group(hid_t parent, const char* name) const {
    Handle gcpl(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
    check(gcpl.ok() && H5Pset_obj_track_times(gcpl.get(), false) >= 0, name);
    Handle g(H5Gcreate2(parent, name, H5P_DEFAULT, gcpl.get(), H5P_DEFAULT), H5Gclose);
    check(g.ok(), name);
    return g;
  }
  // Zygo's attributes are 1-element arrays: prysm reads each as attrs[name][0].
  void number(hid_t obj, const char* name, double v) const {
    const hsize_t one = 1;
    Handle space(H5Screate_simple(1, &one, nullptr), H5Sclose);
    Handle a(H5Acreate2(obj, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose);
    check(a.ok() && H5Awrite(a.get(), H5T_NATIVE_DOUBLE, &v) >= 0, name);
  }
  void text(hid_t obj, const char* name, const std::string& v) const {
    const hsize_t one = 1;
    Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
    check(type.ok() && H5Tset_size(type.get(), H5T_VARIABLE) >= 0 &&
              H5Tset_cset(type.get(), H5T_CSET_UTF8) >= 0,
          name);
    Handle space(H5Screate_simple(1, &one, nullptr), H5Sclose);
    Handle a(H5Acreate2(obj, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    const char* p = v.c_str();
    check(a.ok() && H5Awrite(a.get(), type.get(), &p) >= 0, name);
  }

 private:
  const std::string& path_;
};

void write_surface_dataset(const Writer& w, hid_t file, const ScaledSurface& s,
                           double wavelength_m) {
  const Map& m = s.height_nm;
  std::vector<double> heights(m.size());
  for (std::size_t p = 0; p < m.size(); ++p)
    heights[p] = std::isfinite(m.v[p]) ? m.v[p] : kNoData;
  const Handle data(w.group(file, "Data"));
  const Handle surface(w.group(data.get(), "Surface"));
  const hsize_t dims[2] = {static_cast<hsize_t>(m.height), static_cast<hsize_t>(m.width)};
  Handle space(H5Screate_simple(2, dims, nullptr), H5Sclose);
  Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  w.check(dcpl.ok() && H5Pset_obj_track_times(dcpl.get(), false) >= 0, "the surface");
  Handle d(H5Dcreate2(surface.get(), kOurName, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, dcpl.get(),
                      H5P_DEFAULT),
           H5Dclose);
  w.check(d.ok() && H5Dwrite(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                             heights.data()) >= 0,
          "the surface");
  w.text(d.get(), "Unit", "NanoMeters");
  w.number(d.get(), "No Data", kNoData);
  w.number(d.get(), "Wavelength", wavelength_m);
  w.number(d.get(), "Interferometric Scale Factor", kScaleFactor);
  w.number(d.get(), "Obliquity Factor", 1.0);
  w.text(d.get(), "Title", s.title);
}

// ---------------------------------------------------------------------------------- reading

class Reader {
 public:
  explicit Reader(const std::string& path) : path_(path) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw core::InputError(fmt::format("{}: {}", path_, what));
  }

  // The first (name order) or last child's name of a group: prysm's list(group)[0] / [-1].
  std::string child(hid_t group, const char* group_name, bool last) const {
    H5G_info_t info{};
    if (H5Gget_info(group, &info) < 0 || info.nlinks == 0)
      fail(fmt::format("{} is empty", group_name));
    const hsize_t at = last ? info.nlinks - 1 : 0;
    const ssize_t n =
        H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, at, nullptr, 0, H5P_DEFAULT);
    if (n <= 0 || n > 4096)
      fail(fmt::format("the names in {} cannot be read", group_name));
    std::string name(static_cast<std::size_t>(n) + 1, '\0');
    H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, at, name.data(), name.size(),
                       H5P_DEFAULT);
    name.resize(static_cast<std::size_t>(n));
    return name;
  }

  Handle open_group(hid_t file, const char* name) const {
    if (H5Lexists(file, name + 1, H5P_DEFAULT) <= 0)  // "Data/Surface" exists only if "Data" does
      fail(fmt::format("no group {} (not a Zygo .datx surface)", name));
    Handle g(H5Gopen2(file, name, H5P_DEFAULT), H5Gclose);
    if (!g.ok())
      fail(fmt::format("{} is not a group", name));
    return g;
  }

  // The first value of a numeric attribute; nullopt when there is none of that name.
  std::optional<double> number(hid_t obj, const std::string& where, const char* name) const {
    if (H5Aexists(obj, name) <= 0)
      return std::nullopt;
    const Handle a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
    const Handle type(H5Aget_type(a.get()), H5Tclose);
    const Handle space(H5Aget_space(a.get()), H5Sclose);
    const H5T_class_t c = H5Tget_class(type.get());
    const hssize_t n = H5Sget_simple_extent_npoints(space.get());
    if ((c != H5T_FLOAT && c != H5T_INTEGER) || n < 1 ||
        static_cast<hsize_t>(n) > kMaxAttributeValues)
      fail(fmt::format("{} attribute '{}' is not a number", where, name));
    std::vector<double> v(static_cast<std::size_t>(n));
    if (H5Aread(a.get(), H5T_NATIVE_DOUBLE, v.data()) < 0)
      fail(fmt::format("{} attribute '{}' cannot be read", where, name));
    return v[0];
  }

  // The first string of a string attribute (variable or fixed length); nullopt when absent.
  std::optional<std::string> text(hid_t obj, const std::string& where, const char* name) const {
    if (H5Aexists(obj, name) <= 0)
      return std::nullopt;
    const Handle a(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
    const Handle type(H5Aget_type(a.get()), H5Tclose);
    const Handle space(H5Aget_space(a.get()), H5Sclose);
    const hssize_t n = H5Sget_simple_extent_npoints(space.get());
    if (H5Tget_class(type.get()) != H5T_STRING || n < 1 ||
        static_cast<hsize_t>(n) > kMaxAttributeValues)
      fail(fmt::format("{} attribute '{}' is not text", where, name));
    std::string s;
    if (H5Tis_variable_str(type.get()) > 0) {
      const Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
      H5Tset_size(mem.get(), H5T_VARIABLE);
      H5Tset_cset(mem.get(), H5Tget_cset(type.get()));
      std::vector<char*> p(static_cast<std::size_t>(n), nullptr);
      if (H5Aread(a.get(), mem.get(), p.data()) < 0)
        fail(fmt::format("{} attribute '{}' cannot be read", where, name));
      s = p[0] == nullptr ? "" : p[0];
      for (char* q : p)
        H5free_memory(q);
    } else {
      const std::size_t size = H5Tget_size(type.get());
      std::string buf(size * static_cast<std::size_t>(n), '\0');
      if (size == 0 || H5Aread(a.get(), type.get(), buf.data()) < 0)
        fail(fmt::format("{} attribute '{}' cannot be read", where, name));
      s = buf.substr(0, size);
      s.resize(std::min(s.find('\0'), s.size()));
    }
    return s;
  }

 private:
  const std::string& path_;
};

// Units of a length Zygo writes, per metre; 0 for one it does not know. (Dividing by these keeps
// a length in the unit itself exact: metres / 1 and nanometres / 1e-9 ... would not be.)
double per_metre(const std::string& unit) {
  if (unit == "Meters")
    return 1.0;
  if (unit == "MilliMeters" || unit == "MiliMeters")  // the latter is Zygo's own spelling
    return 1e3;
  if (unit == "MicroMeters")
    return 1e6;
  if (unit == "NanoMeters")
    return 1e9;
  return 0.0;
}

void check_file(const Reader& r, const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st))
    r.fail("no such file");
  if (!fs::is_regular_file(st))
    r.fail("not a regular file");
  const std::uintmax_t bytes = fs::file_size(path, ec);
  if (ec || bytes > io::kMaxFrameFileBytes)
    r.fail(fmt::format("larger than the {} bytes a surface may have", io::kMaxFrameFileBytes));
}

Handle open_file(const Reader& r, const std::string& path) {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
#if H5_VERSION_GE(1, 10, 7)
  H5Pset_file_locking(fapl.get(), false, true);  // read-only: no lock, none needed
#endif
  Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()), H5Fclose);
  if (!f.ok())
    r.fail("not an HDF5 file (or a truncated one): a .datx is HDF5");
  return f;
}

// The heights' scale to nm from the dataset's Unit (and, for fringes, its optics).
double height_scale(const Reader& r, hid_t d, const std::string& where) {
  const std::optional<std::string> unit = r.text(d, where, "Unit");
  if (!unit)
    r.fail(where + " has no 'Unit' attribute");
  if (const double f = per_metre(*unit); f > 0.0)
    return 1e9 / f;  // exactly 1 for NanoMeters: our heights come back as written
  if (*unit != "Fringes")
    r.fail(
        fmt::format("{} 'Unit' = '{}': must be NanoMeters, MicroMeters, MilliMeters, Meters or "
                    "Fringes",
                    where, unit->substr(0, 40)));
  double f = 1e9;  // fringes x obliquity x scale factor x wavelength [m] -> nm
  for (const char* name : {"Wavelength", "Interferometric Scale Factor", "Obliquity Factor"}) {
    const std::optional<double> v = r.number(d, where, name);
    if (!v || !std::isfinite(*v) || !(*v > 0.0))
      r.fail(fmt::format("{} is in fringes but its '{}' is missing or not > 0", where, name));
    f *= *v;
  }
  return f;
}

// Metres on the plate per pixel, from the last group under /Attributes (prysm's choice).
double lateral_scale(const Reader& r, hid_t file) {
  const Handle attributes = r.open_group(file, kAttributesGroup);
  const std::string name = r.child(attributes.get(), kAttributesGroup, true);
  const std::string where = std::string(kAttributesGroup) + "/" + name;
  const Handle g(H5Gopen2(attributes.get(), name.c_str(), H5P_DEFAULT), H5Gclose);
  if (!g.ok())
    r.fail(where + " is not a group");
  const std::optional<double> v = r.number(g.get(), where, kResolutionValue);
  if (!v || !std::isfinite(*v) || !(*v > 0.0))
    r.fail(fmt::format("{} has no '{}' > 0: the map's lateral scale is needed", where,
                       kResolutionValue));
  const std::string unit = r.text(g.get(), where, kResolutionUnit).value_or("Meters");
  const double f = per_metre(unit);
  if (f == 0.0)
    r.fail(fmt::format("{} '{}' = '{}': must be a length", where, kResolutionUnit,
                       unit.substr(0, 40)));
  return *v / f;
}

// The parsing itself, run in the child process of read_datx.
ScaledSurface parse_datx(const std::string& path) {
  silence_hdf5();
  const Reader r(path);
  const Handle file = open_file(r, path);
  const Handle surfaces = r.open_group(file.get(), kSurfaceGroup);
  const std::string name = r.child(surfaces.get(), kSurfaceGroup, false);
  const std::string where = std::string(kSurfaceGroup) + "/" + name;
  const Handle d(H5Dopen2(surfaces.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!d.ok())
    r.fail(where + " is not a dataset");
  const Handle type(H5Dget_type(d.get()), H5Tclose);
  const H5T_class_t c = H5Tget_class(type.get());
  if (c != H5T_FLOAT && c != H5T_INTEGER)
    r.fail(where + " does not hold numbers");
  const Handle space(H5Dget_space(d.get()), H5Sclose);
  hsize_t dims[2] = {0, 0};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank != 2)
    r.fail(fmt::format("{} has {} dimensions: a surface has 2 (rows, columns)", where, rank));
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if (dims[0] < 1 || dims[1] < 1 || dims[0] > kMaxSide || dims[1] > kMaxSide ||
      dims[0] * dims[1] > kMaxFrameSetPixels)
    r.fail(fmt::format("{} is {} x {} pixels: each side must be 1..{} and at most {} pixels in all",
                       where, dims[1], dims[0], kMaxSide, kMaxFrameSetPixels));
  const double nm = height_scale(r, d.get(), where);
  const std::optional<double> no_data = r.number(d.get(), where, "No Data");
  const double m_per_px = lateral_scale(r, file.get());  // before the data: refusals come cheap

  ScaledSurface s;
  s.m_per_px = m_per_px;
  s.height_nm = Map(static_cast<int>(dims[1]), static_cast<int>(dims[0]));
  if (H5Dread(d.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.height_nm.v.data()) < 0)
    r.fail(where + ": its values cannot be read (a truncated or damaged file?)");
  for (double& v : s.height_nm.v)
    v = !std::isfinite(v) || (no_data && v >= *no_data) ? std::numeric_limits<double>::quiet_NaN()
        : nm == 1.0                                     ? v
                                                        : v * nm;
  if (const std::optional<std::string> t = r.text(d.get(), where, "Title"))
    for (const char ch : *t)
      s.title += ch == '\n' || ch == '\r' ? ' ' : ch;
  return s;
}

// ------------------------------------------------------------------- the parsing's process
//
// HDF5 1.10 reads some damaged files out of bounds: one byte of our own file flipped in an
// attribute's header or in the global heap that holds its strings took H5Aexists and H5Aread
// out of their buffers (AddressSanitizer: 7 of 400 flips; 3 of them segfaults without it). So the
// file is parsed in a child process, which sends the map back through a pipe; a child that dies,
// or takes longer than kParseTimeoutMs, leaves an InputError naming the file, not a crash.

constexpr int kParseTimeoutMs = 60'000;  // a 512 MiB file parses in about a second
constexpr std::size_t kMaxTitle = 1024;

struct Wire {  // what the child sends first: 'S' and a map, or 'E' and a message
  char kind = 'E';
  std::int32_t width = 0;
  std::int32_t height = 0;
  double m_per_px = 0.0;
  std::uint32_t text_bytes = 0;  // the title ('S') or the message ('E')
};

bool write_all(int fd, const void* data, std::size_t n) {
  const char* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t k = ::write(fd, p, n);
    if (k < 0 && errno == EINTR)
      continue;
    if (k <= 0)
      return false;
    p += k;
    n -= static_cast<std::size_t>(k);
  }
  return true;
}

[[noreturn]] void child(int fd, const std::string& path) {
  Wire w;
  std::string text;
  ScaledSurface s;
  try {
    s = parse_datx(path);
    w.kind = 'S';
    w.width = s.height_nm.width;
    w.height = s.height_nm.height;
    w.m_per_px = s.m_per_px;
    text = s.title.substr(0, kMaxTitle);
  } catch (const core::InputError& e) {
    text = std::string(e.what()).substr(0, kMaxTitle);
  } catch (...) {
    text = path + ": the HDF5 library could not read it";
  }
  w.text_bytes = static_cast<std::uint32_t>(text.size());
  const bool ok =
      write_all(fd, &w, sizeof w) && write_all(fd, text.data(), text.size()) &&
      (w.kind != 'S' || write_all(fd, s.height_nm.v.data(), s.height_nm.v.size() * sizeof(double)));
  ::_exit(ok ? 0 : 1);  // no atexit handlers: they belong to the parent
}

// Reads exactly n bytes from the child by the deadline; false if it ended or took too long.
bool read_all(int fd, void* data, std::size_t n, std::chrono::steady_clock::time_point deadline) {
  char* p = static_cast<char*>(data);
  while (n > 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0)
      return false;
    pollfd pfd{fd, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, static_cast<int>(left.count()));
    if (ready < 0 && errno == EINTR)
      continue;
    if (ready <= 0)
      return false;
    const ssize_t k = ::read(fd, p, n);
    if (k < 0 && errno == EINTR)
      continue;
    if (k <= 0)
      return false;
    p += k;
    n -= static_cast<std::size_t>(k);
  }
  return true;
}

// The child's answer: the map, or the InputError it gave; nullopt when it gave none.
std::optional<ScaledSurface> receive(int fd) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::milliseconds(kParseTimeoutMs);
  Wire w;
  if (!read_all(fd, &w, sizeof w, deadline) || w.text_bytes > kMaxTitle)
    return std::nullopt;
  std::string text(w.text_bytes, '\0');
  if (!read_all(fd, text.data(), text.size(), deadline))
    return std::nullopt;
  if (w.kind == 'E')
    throw core::InputError(text);
  if (w.kind != 'S' || w.width < 1 || w.height < 1 || w.width > kMaxSide || w.height > kMaxSide ||
      static_cast<std::uint64_t>(w.width) * static_cast<std::uint64_t>(w.height) >
          kMaxFrameSetPixels)
    return std::nullopt;
  ScaledSurface s;
  s.m_per_px = w.m_per_px;
  s.title = std::move(text);
  s.height_nm = Map(w.width, w.height);
  if (!read_all(fd, s.height_nm.v.data(), s.height_nm.v.size() * sizeof(double), deadline))
    return std::nullopt;
  return s;
}

}  // namespace

void write_datx(const std::string& path, const ScaledSurface& s, double wavelength_m) {
  const Map& m = s.height_nm;
  if (m.width < 1 || m.height < 1 || m.size() != static_cast<std::size_t>(m.width) * m.height)
    throw std::invalid_argument("write_datx: an empty map");
  if (!std::isfinite(s.m_per_px) || !(s.m_per_px > 0.0))
    throw std::invalid_argument("write_datx: the lateral scale must be finite and > 0");
  if (!std::isfinite(wavelength_m) || !(wavelength_m > 0.0))
    throw std::invalid_argument("write_datx: the wavelength must be finite and > 0");
  if (s.title.find_first_of(std::string_view("\n\r\0", 3)) != std::string::npos)
    throw std::invalid_argument("write_datx: the title must be one line without NUL");
  silence_hdf5();
  const Writer w(path);
  // Built in memory (HDF5's core driver, no backing store), then written atomically like the
  // .gsf: a reader never sees half a file.
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  w.check(fapl.ok() && H5Pset_fapl_core(fapl.get(), 1 << 20, false) >= 0, "the file");
  std::string image;
  {
    Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), H5Fclose);
    w.check(file.ok(), "the file");
    write_surface_dataset(w, file.get(), s, wavelength_m);
    const Handle attributes(w.group(file.get(), "Attributes"));
    const Handle ours(w.group(attributes.get(), kOurName));
    w.number(ours.get(), kResolutionValue, s.m_per_px);
    w.text(ours.get(), kResolutionUnit, "Meters");
    w.check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL) >= 0, "the file");
    const ssize_t n = H5Fget_file_image(file.get(), nullptr, 0);
    w.check(n > 0, "the file");
    image.resize(static_cast<std::size_t>(n));
    w.check(H5Fget_file_image(file.get(), image.data(), image.size()) == n, "the file");
  }
  io::write_file_atomically(path, image);
}

ScaledSurface read_datx(const std::string& path) {
  const Reader r(path);
  check_file(r, path);  // here: the common refusals need no process
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0)
    r.fail(fmt::format("cannot read it: pipe: {}", std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    r.fail(fmt::format("cannot read it: fork: {}", std::strerror(errno)));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child(fds[1], path);
  }
  ::close(fds[1]);
  std::optional<ScaledSurface> s;
  try {
    s = receive(fds[0]);
  } catch (...) {
    ::close(fds[0]);
    ::waitpid(pid, nullptr, 0);
    throw;
  }
  ::close(fds[0]);
  if (!s)
    ::kill(pid, SIGKILL);  // it may still be running: past the deadline
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!s)
    r.fail(WIFSIGNALED(status)
               ? fmt::format("a damaged HDF5 file: the HDF5 library failed reading it (signal {})",
                             WTERMSIG(status))
               : "a damaged HDF5 file: the HDF5 library failed reading it");
  return std::move(*s);
}

}  // namespace piezoshift::psi
