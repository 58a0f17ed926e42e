// Surface maps in Zygo's .datx layout (surface_datx.hpp): what write_datx wrote read back bit
// for bit, the attributes prysm's read_zygo_datx looks up (read here with HDF5's C library), a
// file in another writer's style (float32 fringes, millimetres, fixed-length strings), and the
// refusals naming the file: not HDF5, truncated, no surface, wrong rank or type, absurd size.
#include <hdf5.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/psi/grid.hpp"
#include "piezoshift/psi/surface_datx.hpp"

namespace piezoshift::psi {
namespace {

namespace fs = std::filesystem;

const double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kResolution = "Data Context.Data Attributes.Resolution:Value";
constexpr const char* kResolutionUnit = "Data Context.Data Attributes.Resolution:Unit";

fs::path temp_dir() {
  const fs::path d =
      fs::temp_directory_path() /
      ("piezoshift_datx_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
       "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string bytes_of(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// A 5 x 3 map in nm: two pixels hold nothing; -0, a subnormal and 0.1 + 0.2 must come back as
// the very same doubles.
ScaledSurface sample() {
  ScaledSurface s;
  s.height_nm = Map(5, 3);
  s.height_nm.v = {1.25, -3.5, kNan, 0.1 + 0.2, -0.0, 4.9e-324, 63.2, 7.0,
                   8.5,  kNan, 2.0,  3.0,       4.0,  -5.0,     6.0};
  s.m_per_px = 0.025 / 117.3;
  s.title = "surface, piston and tilt removed";
  return s;
}

// The HDF5 C library, as a writer that is not ours: files and attributes for the tests.
struct H5File {
  hid_t id;
  explicit H5File(const fs::path& p)
      : id(H5Fcreate(p.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT)) {}
  ~H5File() { H5Fclose(id); }
};

hid_t group(hid_t parent, const char* name) {
  return H5Gcreate2(parent, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
}

void number(hid_t obj, const char* name, double v) {
  const hsize_t one = 1;
  const hid_t s = H5Screate_simple(1, &one, nullptr);
  const hid_t a = H5Acreate2(obj, name, H5T_IEEE_F64LE, s, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_DOUBLE, &v);
  H5Aclose(a);
  H5Sclose(s);
}

// A fixed-length string attribute (h5py's np.bytes_ style), one element.
void fixed_text(hid_t obj, const char* name, const std::string& v) {
  const hsize_t one = 1;
  const hid_t t = H5Tcopy(H5T_C_S1);
  H5Tset_size(t, v.size() + 1);
  const hid_t s = H5Screate_simple(1, &one, nullptr);
  const hid_t a = H5Acreate2(obj, name, t, s, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, t, v.c_str());
  H5Aclose(a);
  H5Sclose(s);
  H5Tclose(t);
}

// The first string of an attribute written by write_datx (variable length).
std::string read_text(hid_t obj, const char* name) {
  const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  const hid_t t = H5Aget_type(a);
  EXPECT_GT(H5Tis_variable_str(t), 0) << name;
  char* p = nullptr;
  H5Aread(a, t, &p);
  std::string s = p == nullptr ? "" : p;
  H5free_memory(p);
  H5Tclose(t);
  H5Aclose(a);
  return s;
}

double read_number(hid_t obj, const char* name) {
  const hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
  const hid_t sp = H5Aget_space(a);
  EXPECT_EQ(H5Sget_simple_extent_npoints(sp), 1) << name;  // prysm reads attrs[name][0]
  double v = kNan;
  H5Aread(a, H5T_NATIVE_DOUBLE, &v);
  H5Sclose(sp);
  H5Aclose(a);
  return v;
}

TEST(DatxFileTest, WhatWasWrittenReadsBackBitForBit) {
  const fs::path d = temp_dir();
  const ScaledSurface s = sample();
  write_datx((d / "surface_nm.datx").string(), s, 632.8e-9);
  const ScaledSurface r = read_datx((d / "surface_nm.datx").string());
  ASSERT_EQ(r.height_nm.width, 5);
  ASSERT_EQ(r.height_nm.height, 3);
  for (std::size_t p = 0; p < s.height_nm.size(); ++p) {
    if (std::isnan(s.height_nm.v[p])) {
      EXPECT_TRUE(std::isnan(r.height_nm.v[p])) << p;
    } else {
      EXPECT_EQ(std::memcmp(&s.height_nm.v[p], &r.height_nm.v[p], sizeof(double)), 0)
          << p << ": " << s.height_nm.v[p] << " read back as " << r.height_nm.v[p];
    }
  }
  EXPECT_EQ(r.m_per_px, s.m_per_px);
  EXPECT_EQ(r.title, s.title);
  // Written again: the same bytes (no time stamps in the objects).
  write_datx((d / "again.datx").string(), r, 632.8e-9);
  EXPECT_TRUE(bytes_of(d / "surface_nm.datx") == bytes_of(d / "again.datx"));
  fs::remove_all(d);
}

TEST(DatxFileTest, TheLayoutIsWhatPrysmsReaderLooksUp) {
  const fs::path d = temp_dir();
  const ScaledSurface s = sample();
  write_datx((d / "s.datx").string(), s, 632.8e-9);
  const hid_t f = H5Fopen((d / "s.datx").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const hid_t ds = H5Dopen2(f, "/Data/Surface/Piezoshift", H5P_DEFAULT);
  ASSERT_GE(ds, 0);
  const hid_t space = H5Dget_space(ds);
  hsize_t dims[2] = {0, 0};
  EXPECT_EQ(H5Sget_simple_extent_ndims(space), 2);
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ(dims[0], 3u);  // rows
  EXPECT_EQ(dims[1], 5u);  // columns
  std::vector<double> v(15);
  H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  EXPECT_EQ(v[0], 1.25);  // row 0 at the top, as the map
  EXPECT_EQ(v[3], 0.1 + 0.2);
  EXPECT_EQ(v[2], std::numeric_limits<double>::max());  // no value: the No Data value
  EXPECT_EQ(read_text(ds, "Unit"), "NanoMeters");
  EXPECT_EQ(read_number(ds, "No Data"), std::numeric_limits<double>::max());
  EXPECT_EQ(read_number(ds, "Wavelength"), 632.8e-9);
  EXPECT_EQ(read_number(ds, "Interferometric Scale Factor"), 0.5);
  EXPECT_EQ(read_number(ds, "Obliquity Factor"), 1.0);
  const hid_t g = H5Gopen2(f, "/Attributes/Piezoshift", H5P_DEFAULT);
  ASSERT_GE(g, 0);
  EXPECT_EQ(read_number(g, kResolution), s.m_per_px);
  EXPECT_EQ(read_text(g, kResolutionUnit), "Meters");
  H5Gclose(g);
  H5Sclose(space);
  H5Dclose(ds);
  H5Fclose(f);
  fs::remove_all(d);
}

TEST(DatxFileTest, AnotherWritersFloat32FringesInMillimetresAreRead) {
  const fs::path d = temp_dir();
  const fs::path p = d / "zygo.datx";
  {
    H5File f(p);
    const hid_t data = group(f.id, "Data");
    const hid_t surf = group(data, "Surface");
    const hsize_t dims[2] = {2, 3};
    const hid_t sp = H5Screate_simple(2, dims, nullptr);
    const hid_t ds =
        H5Dcreate2(surf, "{8A1C}", H5T_IEEE_F32LE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const float v[6] = {0.5f, -0.25f, 1e38f, 0.0f, std::numeric_limits<float>::quiet_NaN(), 2.0f};
    H5Dwrite(ds, H5T_NATIVE_FLOAT, H5S_ALL, H5S_ALL, H5P_DEFAULT, v);
    fixed_text(ds, "Unit", "Fringes");
    number(ds, "No Data", static_cast<double>(1e38f));  // as the float32 data holds it
    number(ds, "Wavelength", 632.8e-9);
    number(ds, "Interferometric Scale Factor", 0.5);
    number(ds, "Obliquity Factor", 1.0);
    const hid_t attrs = group(f.id, "Attributes");
    const hid_t first = group(attrs, "{0001}");  // prysm reads the last group's
    number(first, kResolution, 99.0);
    const hid_t last = group(attrs, "{0002}");
    number(last, kResolution, 0.125);
    fixed_text(last, kResolutionUnit, "MiliMeters");  // Zygo's spelling
    for (const hid_t id : {last, first, attrs, surf, data})
      H5Gclose(id);
    H5Dclose(ds);
    H5Sclose(sp);
  }
  const ScaledSurface r = read_datx(p.string());
  ASSERT_EQ(r.height_nm.width, 3);
  ASSERT_EQ(r.height_nm.height, 2);
  EXPECT_DOUBLE_EQ(r.m_per_px, 0.125e-3);
  EXPECT_DOUBLE_EQ(r.height_nm.v[0], 0.5 * 0.5 * 632.8);  // fringes x scale factor x wavelength
  EXPECT_DOUBLE_EQ(r.height_nm.v[1], -0.25 * 0.5 * 632.8);
  EXPECT_TRUE(std::isnan(r.height_nm.v[2]));  // >= No Data
  EXPECT_TRUE(std::isnan(r.height_nm.v[4]));  // NaN
  EXPECT_DOUBLE_EQ(r.height_nm.v[5], 2.0 * 0.5 * 632.8);
  EXPECT_EQ(r.title, "");
  fs::remove_all(d);
}

// Each bad file is refused as an InputError that names it and what is wrong.
void expect_refused(const fs::path& p, const std::string& needle) {
  try {
    read_datx(p.string());
    ADD_FAILURE() << "accepted: " << needle;
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(p.string() + ": "), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

// A file with /Data/Surface/s of the given type and dimensions (chunked: nothing is stored, so
// an absurd size costs no disk), Unit NanoMeters, and a resolution.
void dataset_file(const fs::path& p, hid_t type, std::vector<hsize_t> dims) {
  H5File f(p);
  const hid_t data = group(f.id, "Data");
  const hid_t surf = group(data, "Surface");
  const hid_t sp = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
  std::vector<hsize_t> chunk(dims.size(), 1);
  H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data());
  const hid_t ds = H5Dcreate2(surf, "s", type, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT);
  fixed_text(ds, "Unit", "NanoMeters");
  const hid_t attrs = group(f.id, "Attributes");
  const hid_t g = group(attrs, "a");
  number(g, kResolution, 1e-4);
  for (const hid_t id : {g, attrs, surf, data})
    H5Gclose(id);
  H5Dclose(ds);
  H5Pclose(dcpl);
  H5Sclose(sp);
}

TEST(DatxFileTest, BadFilesAreRefusedNamingThemAndWhy) {
  const fs::path d = temp_dir();
  const fs::path p = d / "bad.datx";
  std::ofstream(p) << "not HDF5 at all";
  expect_refused(p, "not an HDF5 file");
  // Ours, cut in half.
  write_datx((d / "good.datx").string(), sample(), 632.8e-9);
  const std::string good = bytes_of(d / "good.datx");
  std::ofstream(p, std::ios::binary | std::ios::trunc) << good.substr(0, good.size() / 2);
  expect_refused(p, "not an HDF5 file (or a truncated one)");
  { H5File f(p); }  // HDF5, nothing in it
  expect_refused(p, "no group /Data/Surface");
  dataset_file(p, H5T_IEEE_F64LE, {2, 3, 4});
  expect_refused(p, "/Data/Surface/s has 3 dimensions: a surface has 2");
  dataset_file(p, H5T_IEEE_F64LE, {20000, 20000});
  expect_refused(p, "/Data/Surface/s is 20000 x 20000 pixels: each side must be 1..16384");
  dataset_file(p, H5T_IEEE_F64LE, {16384, 16384});
  expect_refused(p, "at most 67108864 pixels in all");
  const hid_t str = H5Tcopy(H5T_C_S1);
  H5Tset_size(str, 8);
  dataset_file(p, str, {2, 2});
  H5Tclose(str);
  expect_refused(p, "/Data/Surface/s does not hold numbers");
  {
    H5File f(p);
    H5Gclose(group(f.id, "Data"));
    const hid_t data = H5Gopen2(f.id, "Data", H5P_DEFAULT);
    H5Gclose(group(data, "Surface"));
    H5Gclose(data);
  }
  expect_refused(p, "/Data/Surface is empty");
  expect_refused(d / "absent.datx", "no such file");
  expect_refused(d, "not a regular file");
  fs::remove_all(d);
}

// HDF5 1.10.8 reads some damaged files out of bounds: one byte flipped of a 40 x 30 map's file
// (found by flipping every 7th byte: 7 of 400 under AddressSanitizer, heap overflows in
// H5Aexists and H5Aread). Three of them are segfaults of the library (signal 11, release build):
// before the parse ran in a child process, `psi compare` died on them. Now those are refused
// naming the file, and none of the seven ends the test process. (With another HDF5 version other
// bytes may be the ones.)
TEST(DatxFileTest, FilesThatCrashHdf5AreRefusedNotACrashOfTheProgram) {
  const fs::path d = temp_dir();
  ScaledSurface s;
  s.height_nm = Map(40, 30);
  for (std::size_t p = 0; p < s.height_nm.size(); ++p)
    s.height_nm.v[p] = p % 7 != 0 ? static_cast<double>(p) * 0.1 : kNan;
  s.m_per_px = 1e-4;
  s.title = "t";
  write_datx((d / "a.datx").string(), s, 632.8e-9);
  const std::string good = bytes_of(d / "a.datx");
  const auto flipped = [&](std::size_t at) {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ 0x5a);
    const fs::path p = d / ("flip" + std::to_string(at) + ".datx");
    std::ofstream(p, std::ios::binary) << bad;
    return p;
  };
  ASSERT_EQ(good.size(), 19624u);  // the layout these offsets were found in
  for (const std::size_t at : {3094u, 13090u, 13146u})
    expect_refused(flipped(at), "a damaged HDF5 file: the HDF5 library failed reading it");
  for (const std::size_t at : {17255u, 17542u, 17556u, 19621u}) {
    try {
      read_datx(flipped(at).string());
    } catch (const core::InputError&) {
    }
  }
  fs::remove_all(d);
}

TEST(DatxFileTest, UnknownUnitsAndAMissingScaleAreRefused) {
  const fs::path d = temp_dir();
  const fs::path p = d / "bad.datx";
  dataset_file(p, H5T_IEEE_F64LE, {2, 2});
  {
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t ds = H5Dopen2(f, "/Data/Surface/s", H5P_DEFAULT);
    H5Adelete(ds, "Unit");
    fixed_text(ds, "Unit", "Volts");
    H5Dclose(ds);
    H5Fclose(f);
  }
  expect_refused(p, "/Data/Surface/s 'Unit' = 'Volts': must be NanoMeters");
  dataset_file(p, H5T_IEEE_F64LE, {2, 2});
  {
    const hid_t f = H5Fopen(p.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t g = H5Gopen2(f, "/Attributes/a", H5P_DEFAULT);
    H5Adelete(g, kResolution);
    H5Gclose(g);
    H5Fclose(f);
  }
  expect_refused(p, "/Attributes/a has no 'Data Context.Data Attributes.Resolution:Value' > 0");
  fs::remove_all(d);
}

TEST(DatxFileTest, TheWriterRefusesWhatItCannotWrite) {
  const fs::path d = temp_dir();
  ScaledSurface s = sample();
  EXPECT_THROW(write_datx((d / "a.datx").string(), s, 0.0), std::invalid_argument);
  s.m_per_px = kNan;
  EXPECT_THROW(write_datx((d / "a.datx").string(), s, 632.8e-9), std::invalid_argument);
  s = sample();
  s.title = "two\nlines";
  EXPECT_THROW(write_datx((d / "a.datx").string(), s, 632.8e-9), std::invalid_argument);
  EXPECT_FALSE(fs::exists(d / "a.datx"));
  fs::remove_all(d);
}

}  // namespace
}  // namespace piezoshift::psi
