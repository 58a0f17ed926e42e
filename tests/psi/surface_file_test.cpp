// Gwyddion Simple Field files (surface_file.hpp): the layout of gwyddion.net's specification byte
// by byte, what was written read back bit for bit, a file from elsewhere in other units, the
// refusals naming the file; and the comparison of two maps (surface_comparison.hpp).
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
#include "piezoshift/psi/surface_comparison.hpp"
#include "piezoshift/psi/surface_file.hpp"
#include "piezoshift/psi/zernike.hpp"

namespace piezoshift::psi {
namespace {

namespace fs = std::filesystem;

const double kNan = std::numeric_limits<double>::quiet_NaN();

fs::path temp_dir() {
  const fs::path d =
      fs::temp_directory_path() /
      ("piezoshift_gsf_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
       ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string bytes_of(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void put(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

// A 5 x 3 map in nm with two pixels that hold nothing.
ScaledSurface sample() {
  ScaledSurface s;
  s.height_nm = Map(5, 3);
  s.height_nm.v = {1.25, -3.5, kNan, 12.345678, 0.0, -0.001, 63.2, 7.0,
                   8.5,  kNan, 2.0,  3.0,       4.0, -5.0,   6.0};
  s.m_per_px = 0.025 / 117.3;
  s.title = "surface, piston and tilt removed";
  return s;
}

// The header text of a GSF: from the magic line to the first NUL.
std::string header_of(const std::string& bytes) {
  return bytes.substr(0, bytes.find('\0'));
}

TEST(GsfFileTest, TheLayoutIsTheSpecificationsByteForByte) {
  const fs::path d = temp_dir();
  const ScaledSurface s = sample();
  write_gsf((d / "surface_m.gsf").string(), s);
  const std::string b = bytes_of(d / "surface_m.gsf");
  const std::string h = header_of(b);
  EXPECT_EQ(h.rfind("Gwyddion Simple Field 1.0\n", 0), 0u);
  EXPECT_NE(h.find("\nXRes = 5\n"), std::string::npos) << h;
  EXPECT_NE(h.find("\nYRes = 3\n"), std::string::npos);
  EXPECT_NE(h.find("\nXYUnits = m\n"), std::string::npos);
  EXPECT_NE(h.find("\nZUnits = m\n"), std::string::npos);
  EXPECT_NE(h.find("\nTitle = surface, piston and tilt removed\n"), std::string::npos);
  EXPECT_NE(h.find("\nPiezoshiftMask = surface_m_mask.gsf\n"), std::string::npos);
  // XReal is the field's width in metres, to 17 digits.
  const std::size_t x = h.find("XReal = ");
  ASSERT_NE(x, std::string::npos);
  EXPECT_DOUBLE_EQ(std::stod(h.substr(x + 8)), 5 * s.m_per_px);
  // 1 to 4 NULs, the data at a multiple of 4, then exactly XRes * YRes float32.
  const std::size_t data = (h.size() / 4 + 1) * 4;
  for (std::size_t i = h.size(); i < data; ++i)
    EXPECT_EQ(b[i], '\0') << i;
  ASSERT_EQ(b.size(), data + 15 * 4);
  float first = 0.0f;
  std::memcpy(&first, b.data() + data, 4);  // little endian on this machine (static_assert)
  EXPECT_EQ(first, static_cast<float>(1.25e-9));
  float hole = 1.0f;
  std::memcpy(&hole, b.data() + data + 2 * 4, 4);
  EXPECT_EQ(hole, 0.0f);  // GSF has no invalid value: 0 m, and the mask says so
  // The mask: the same size and scale, 1 where a value is, 0 where none.
  const std::string m = bytes_of(d / "surface_m_mask.gsf");
  const std::string mh = header_of(m);
  EXPECT_NE(mh.find("\nXReal = " + h.substr(x + 8, h.find('\n', x) - x - 8) + "\n"),
            std::string::npos);
  EXPECT_EQ(mh.find("ZUnits"), std::string::npos);  // a count, not a length
  const std::size_t md = (mh.size() / 4 + 1) * 4;
  ASSERT_EQ(m.size(), md + 15 * 4);
  std::vector<float> valid(15);
  std::memcpy(valid.data(), m.data() + md, 15 * 4);
  for (std::size_t p = 0; p < 15; ++p)
    EXPECT_EQ(valid[p], std::isfinite(s.height_nm.v[p]) ? 1.0f : 0.0f) << p;
  fs::remove_all(d);
}

TEST(GsfFileTest, WhatWasWrittenReadsBackBitForBit) {
  const fs::path d = temp_dir();
  const ScaledSurface s = sample();
  write_gsf((d / "a.gsf").string(), s);
  const ScaledSurface r = read_gsf((d / "a.gsf").string());
  ASSERT_EQ(r.height_nm.width, 5);
  ASSERT_EQ(r.height_nm.height, 3);
  for (std::size_t p = 0; p < s.height_nm.size(); ++p) {
    if (std::isfinite(s.height_nm.v[p]))  // the float32 metres written, as nm
      EXPECT_EQ(r.height_nm.v[p], static_cast<float>(s.height_nm.v[p] * 1e-9) * 1e9) << p;
    else
      EXPECT_TRUE(std::isnan(r.height_nm.v[p])) << p;
  }
  EXPECT_NEAR(r.m_per_px, s.m_per_px, 1e-15 * s.m_per_px);
  EXPECT_EQ(r.title, s.title);
  // Written again from what was read: the same bytes, surface and mask (but the mask's name).
  write_gsf((d / "b.gsf").string(), r);
  std::string again = bytes_of(d / "b.gsf");
  const std::size_t name = again.find("b_mask.gsf");
  ASSERT_NE(name, std::string::npos);
  again[name] = 'a';
  EXPECT_EQ(bytes_of(d / "a.gsf"), again);
  EXPECT_EQ(bytes_of(d / "a_mask.gsf"), bytes_of(d / "b_mask.gsf"));
  // A map where every pixel holds a value has no mask.
  ScaledSurface full = s;
  full.height_nm.v[2] = full.height_nm.v[9] = 1.0;
  write_gsf((d / "full.gsf").string(), full);
  EXPECT_FALSE(fs::exists(d / "full_mask.gsf"));
  EXPECT_EQ(header_of(bytes_of(d / "full.gsf")).find("PiezoshiftMask"), std::string::npos);
  EXPECT_TRUE(std::isfinite(read_gsf((d / "full.gsf").string()).height_nm.v[2]));
  fs::remove_all(d);
}

TEST(GsfFileTest, AFileFromElsewhereInOtherUnitsAndWithNonFiniteValues) {
  const fs::path d = temp_dir();
  // Another writer's style: no spaces, extra fields, micrometres of height, mm across, NaN.
  std::string h =
      "Gwyddion Simple Field 1.0\nXRes=2\nYRes=2\n  XReal = 1.5 \nYReal=1.5\nXYUnits=mm\n"
      "ZUnits=um\nTitle=Height\nXOffset=0.1\nVendorKey = 33\n";
  h.append(4 - h.size() % 4, '\0');
  const float v[4] = {0.5f, -0.25f, std::numeric_limits<float>::quiet_NaN(),
                      std::numeric_limits<float>::infinity()};
  h.append(reinterpret_cast<const char*>(v), sizeof v);
  put(d / "other.gsf", h);
  const ScaledSurface r = read_gsf((d / "other.gsf").string());
  EXPECT_DOUBLE_EQ(r.m_per_px, 0.75e-3);
  EXPECT_DOUBLE_EQ(r.height_nm.v[0], 500.0);
  EXPECT_DOUBLE_EQ(r.height_nm.v[1], -250.0);
  EXPECT_TRUE(std::isnan(r.height_nm.v[2]));
  EXPECT_TRUE(std::isnan(r.height_nm.v[3]));
  EXPECT_EQ(r.title, "Height");
  fs::remove_all(d);
}

// Each bad file is refused as an InputError that names it and what is wrong.
void expect_refused(const fs::path& p, const std::string& bytes, const std::string& needle) {
  put(p, bytes);
  try {
    read_gsf(p.string());
    ADD_FAILURE() << "accepted: " << needle;
  } catch (const core::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(p.string()), std::string::npos) << what;
    EXPECT_NE(what.find(needle), std::string::npos) << what;
  }
}

std::string gsf(const std::string& fields, std::size_t floats) {
  std::string h = "Gwyddion Simple Field 1.0\n" + fields;
  h.append(4 - h.size() % 4, '\0');
  h.append(floats * 4, '\0');
  return h;
}

TEST(GsfFileTest, BadFilesAreRefusedNamingThemAndWhy) {
  const fs::path d = temp_dir();
  const fs::path p = d / "bad.gsf";
  const std::string units = "XReal = 1\nYReal = 1\nXYUnits = m\nZUnits = m\n";
  expect_refused(p, "P5\n2 2\n255\n", "not a Gwyddion Simple Field file");
  expect_refused(p, "Gwyddion Simple Field 1.0\nXRes = 2\n", "no NUL");
  expect_refused(p, gsf("YRes = 2\n" + units, 4), "no XRes");
  expect_refused(p, gsf("XRes = 0\nYRes = 2\n" + units, 0), "XRes = 0: must be a whole number");
  expect_refused(p, gsf("XRes = 2x\nYRes = 2\n" + units, 4), "XRes = 2x");
  expect_refused(p, gsf("XRes = 99999\nYRes = 99999\n" + units, 4), "XRes = 99999");
  expect_refused(p, gsf("XRes = 2\nYRes = 2\n" + units, 3), "XRes x YRes = 2 x 2 needs 16");
  expect_refused(p, gsf("XRes = 2\nYRes = 2\n" + units, 5), "20 bytes of data");
  expect_refused(p, gsf("XRes = 2\nYRes = 2\nnonsense\n" + units, 4), "is not 'name = value'");
  expect_refused(p, gsf("XRes = 2\nXRes = 2\nYRes = 2\n" + units, 4), "XRes is given twice");
  expect_refused(p, gsf("XRes = 2\nYRes = 2\nXReal = 1\nYReal = 2\nXYUnits = m\nZUnits = m\n", 4),
                 "not square");
  expect_refused(p, gsf("XRes = 2\nYRes = 2\nXReal = 1\nYReal = 1\nXYUnits = V\nZUnits = m\n", 4),
                 "XYUnits = V: must be a length");
  expect_refused(p, gsf("XRes = 2\nYRes = 2\nXReal = 1\nYReal = 1\nXYUnits = m\n", 4),
                 "ZUnits = (none): must be a length");
  expect_refused(p, gsf("XRes = 2\nYRes = 2\nXReal = nan\nYReal = 1\nXYUnits = m\nZUnits = m\n", 4),
                 "XReal = nan: must be a number > 0");
  expect_refused(p, gsf("XRes = 2\nYRes = 2\n" + units + "PiezoshiftMask = ../x.gsf\n", 4),
                 "must be the name of a file beside it");
  // A mask of another size, or holding something other than 0 and 1, names the mask.
  put(d / "m.gsf", gsf("XRes = 3\nYRes = 2\nXReal = 1.5\nYReal = 1\nXYUnits = m\n", 6));
  put(p, gsf("XRes = 2\nYRes = 2\n" + units + "PiezoshiftMask = m.gsf\n", 4));
  try {
    read_gsf(p.string());
    ADD_FAILURE() << "a mask of another size was accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find((d / "m.gsf").string() + ": the mask is 3 x 2"),
              std::string::npos)
        << e.what();
  }
  std::string two = gsf("XRes = 2\nYRes = 2\nXReal = 1\nYReal = 1\nXYUnits = m\n", 0);
  const float v[4] = {1.0f, 0.0f, 2.0f, 1.0f};
  two.append(reinterpret_cast<const char*>(v), sizeof v);
  put(d / "m.gsf", two);
  try {
    read_gsf(p.string());
    ADD_FAILURE() << "a mask holding 2 was accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pixel (0, 1) is 2: a mask holds 0 or 1"),
              std::string::npos)
        << e.what();
  }
  // A missing file is named too.
  EXPECT_THROW(read_gsf((d / "absent.gsf").string()), core::InputError);
  fs::remove_all(d);
}

TEST(SurfaceComparisonTest, TheDifferenceItsRmsAndItsZernikeTermsOverTheCommonPixels) {
  const Mask disk = disk_mask(64, 64, 30.0);
  const std::vector<double> ca{0.0, 0.0, 0.0, 20.0, 5.0, -3.0};
  const std::vector<double> cb{0.0, 1.5, 0.0, 22.0, 5.0, -3.0};  // tilt x and 2 nm more power
  const Map a = zernike_surface(ca, disk);
  Map b = zernike_surface(cb, disk);
  b.at(32, 5) = kNan;  // a pixel b lacks is left out of everything
  const SurfaceComparison c = compare_surfaces(a, b, 37);
  EXPECT_EQ(c.pixels, disk.count() - 1);
  EXPECT_TRUE(std::isnan(c.difference_nm.at(32, 5)));
  ASSERT_EQ(c.zernike_difference_nm.size(), 37u);
  // The pupil of the common pixels (one fewer) is not quite the disk the terms were drawn on.
  EXPECT_NEAR(c.zernike_a_nm[3], 20.0, 0.02);
  EXPECT_NEAR(c.zernike_b_nm[3], 22.0, 0.02);
  EXPECT_NEAR(c.zernike_difference_nm[1], 1.5, 0.002);
  EXPECT_NEAR(c.zernike_difference_nm[3], 2.0, 0.002);
  EXPECT_NEAR(c.zernike_difference_nm[4], 0.0, 0.002);
  for (std::size_t j = 0; j < 37; ++j)  // one fit over one set of pixels: linear
    EXPECT_NEAR(c.zernike_difference_nm[j], c.zernike_b_nm[j] - c.zernike_a_nm[j], 1e-9) << j;
  // Piston and tilt removed, what is left is the 2 nm of power (RMS 2 on the disk, nearly).
  EXPECT_NEAR(c.rms_tilt_removed_nm, 2.0, 0.05);
  EXPECT_GT(c.rms_nm, c.rms_tilt_removed_nm);
  const SurfaceComparison same = compare_surfaces(a, a, 37);
  EXPECT_EQ(same.rms_nm, 0.0);
  EXPECT_EQ(same.pv_nm, 0.0);
  EXPECT_THROW(compare_surfaces(a, Map(32, 64), 37), std::invalid_argument);
  EXPECT_THROW(compare_surfaces(a, Map(64, 64, kNan), 37), std::invalid_argument);
}

}  // namespace
}  // namespace piezoshift::psi
