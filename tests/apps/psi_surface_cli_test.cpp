// `psi analyze`'s surface_m.gsf opened by readers that are not ours: Gwyddion itself (its
// gwyddion-thumbnailer loads the file with Gwyddion's GSF module and states the field's pixels
// and real size) and a reader written here in Python from gwyddion.net's specification (numpy),
// which checks the layout and gives the heights; then `psi compare` of two such maps, and its
// refusals (sizes, lateral scales, unreadable files), each naming what is wrong. The same
// surface as surface_nm.datx (Zygo's HDF5 layout) read by h5py the way prysm reads it, and by
// psi compare, whose refusals of a bad .datx name the file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/cli_test.hpp"
#include "piezoshift/psi/npy.hpp"
#include "piezoshift/psi/surface_datx.hpp"
#include "piezoshift/psi/surface_file.hpp"

namespace piezoshift {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// gwyddion.net's "Gwyddion Simple Field" read independently of src/psi: magic line, name = value
// lines, 1..4 NULs to a multiple of 4, XRes * YRes little-endian float32 filling the rest.
constexpr const char* kPythonReader = R"PY(
import json, sys
import numpy as np
raw = open(sys.argv[1], 'rb').read()
magic = b'Gwyddion Simple Field 1.0\n'
assert raw.startswith(magic), 'magic'
end = raw.index(b'\0')
fields = {}
for line in raw[len(magic):end].decode('utf-8').split('\n'):
    if line.strip():
        name, value = line.split('=', 1)
        fields[name.strip()] = value.strip()
start = end + 4 - end % 4
assert start % 4 == 0 and set(raw[end:start]) == {0}, 'padding'
xres, yres = int(fields['XRes']), int(fields['YRes'])
data = np.frombuffer(raw[start:], dtype='<f4')
assert data.size == xres * yres, 'size'
z = data.reshape(yres, xres).astype(np.float64)
valid = np.ones_like(z, dtype=bool)
if 'PiezoshiftMask' in fields:
    m = open(sys.argv[1].rsplit('/', 1)[0] + '/' + fields['PiezoshiftMask'], 'rb').read()
    e = m.index(b'\0')
    valid = np.frombuffer(m[e + 4 - e % 4:], dtype='<f4').reshape(yres, xres) == 1.0
print(json.dumps({'xres': xres, 'yres': yres, 'xreal': float(fields['XReal']),
                  'yreal': float(fields['YReal']), 'xyunits': fields['XYUnits'],
                  'zunits': fields['ZUnits'], 'title': fields.get('Title', ''),
                  'valid': int(valid.sum()), 'min': float(z[valid].min()),
                  'max': float(z[valid].max()), 'centre': float(z[yres // 2, xres // 2]),
                  'outside': float(z[0, 0])}))
)PY";

// The tEXt chunks of a PNG: Gwyddion's thumbnail states the field it loaded.
std::string png_text(const std::string& png, const std::string& key) {
  for (std::size_t i = 8; i + 12 <= png.size();) {
    const std::size_t n = (static_cast<unsigned char>(png[i]) << 24) |
                          (static_cast<unsigned char>(png[i + 1]) << 16) |
                          (static_cast<unsigned char>(png[i + 2]) << 8) |
                          static_cast<unsigned char>(png[i + 3]);
    if (png.compare(i + 4, 4, "tEXt") == 0) {
      const std::string chunk = png.substr(i + 8, n);
      const std::size_t nul = chunk.find('\0');
      if (chunk.substr(0, nul) == key)
        return chunk.substr(nul + 1);
    }
    i += 12 + n;
  }
  return {};
}

class PsiSurfaceCliTest : public testing::CliTest {
 protected:
  std::string simulate(const std::string& name, int size) {
    const testing::CliResult r = run("psi simulate --out '" + path(name) + "' --size " +
                                     std::to_string(size) + " --no-budget --json");
    EXPECT_EQ(r.status, 0) << r.err;
    return path(name);
  }
  // psi analyze of a simulated set into out; its JSON.
  Json analyze(const std::string& sim, const std::string& out, const std::string& extra = "") {
    std::string frames;
    for (int k = 0; k < 5; ++k)
      frames += " '" + sim + "/frame_0" + std::to_string(k) + ".png'";
    const testing::CliResult r = run("psi analyze" + frames + " --mask '" + sim + "/mask.png' " +
                                     extra + " --out '" + out + "' --json");
    EXPECT_EQ(r.status, 0) << r.err;
    return r.status == 0 ? Json::parse(r.out) : Json{};
  }
  void expect_refused(const std::string& args, const std::string& needle) {
    const testing::CliResult r = run(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  }
};

TEST_F(PsiSurfaceCliTest, GwyddionAndAnIndependentReaderOpenTheSurfaceWithItsScale) {
  const std::string sim = simulate("sim", 64);
  const Json j = analyze(sim, path("a"));
  const double radius_px = j["pupil"]["radius_px"].get<double>();
  const double m_per_px = j["lateral_scale_m_per_px"].get<double>();
  EXPECT_DOUBLE_EQ(m_per_px, 0.025 / radius_px);  // [camera] pupil_radius_m over the pupil's px
  const std::string gsf = path("a") + "/surface_m.gsf";
  ASSERT_TRUE(fs::exists(gsf));
  ASSERT_TRUE(fs::exists(path("a") + "/surface_m_mask.gsf"));

  // Gwyddion (Debian's gwyddion): its thumbnailer loads the file through Gwyddion's own GSF
  // module and writes the field's pixels and real size into the PNG.
  const std::string png = path("thumb.png");
  const std::string cmd = "gwyddion-thumbnailer kde4 256 '" + gsf + "' > '" + png + "'";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const std::string thumb = testing::slurp(png);
  EXPECT_EQ(png_text(thumb, "Thumb::Image::Width"), "64");
  EXPECT_EQ(png_text(thumb, "Thumb::Image::Height"), "64");
  // "0.053×0.053 m": Gwyddion's own rounding and unit of XReal x YReal
  const std::string real = png_text(thumb, "Thumb::X-Gwyddion::RealSize");
  const std::size_t space = real.rfind(' ');
  ASSERT_NE(space, std::string::npos) << real;
  const std::string unit = real.substr(space + 1);
  const double metres = unit == "m" ? 1.0 : unit == "mm" ? 1e-3 : 0.0;
  ASSERT_GT(metres, 0.0) << real;
  EXPECT_NEAR(std::stod(real) * metres, 64 * m_per_px, 0.01 * 64 * m_per_px) << real;

  // The independent reader: layout, scale, units and the heights of the .npy, in metres.
  const std::string script = path("read_gsf.py");
  std::ofstream(script) << kPythonReader;
  const std::string out = path("py.json");
  const std::string py = "/usr/bin/python3 '" + script + "' '" + gsf + "' > '" + out + "'";
  ASSERT_EQ(std::system(py.c_str()), 0) << py;
  const Json r = Json::parse(testing::slurp(out));
  EXPECT_EQ(r["xres"], 64);
  EXPECT_EQ(r["yres"], 64);
  EXPECT_NEAR(r["xreal"].get<double>(), 64 * m_per_px, 1e-15);
  EXPECT_NEAR(r["yreal"].get<double>(), 64 * m_per_px, 1e-15);
  EXPECT_EQ(r["xyunits"], "m");
  EXPECT_EQ(r["zunits"], "m");
  const psi::Map s = psi::read_npy(path("a") + "/surface_nm.npy");
  double lo = 1e300, hi = -1e300;
  int valid = 0;
  for (const double v : s.v)
    if (std::isfinite(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      ++valid;
    }
  EXPECT_EQ(r["valid"], valid);
  EXPECT_EQ(r["valid"], j["valid_pixels"]);
  EXPECT_NEAR(r["min"].get<double>(), lo * 1e-9, 1e-7 * std::fabs(lo) * 1e-9);  // float32
  EXPECT_NEAR(r["max"].get<double>(), hi * 1e-9, 1e-7 * std::fabs(hi) * 1e-9);
  EXPECT_NEAR(r["centre"].get<double>(), s.at(32, 32) * 1e-9,
              1e-7 * std::fabs(s.at(32, 32)) * 1e-9);
  EXPECT_GT(hi - lo, 10.0);      // nm: the simulated part's figure, not a blank
  EXPECT_EQ(r["outside"], 0.0);  // outside the pupil: 0 m, masked
}

// surface_nm.datx through h5py (Debian's python3-h5py) as prysm 0.21.1's read_zygo_datx reads
// it (tests/support/read_datx_h5py.py): the .npy's doubles bit for bit, the lateral scale, the
// units; read back by read_datx bit for bit; the height range Gwyddion sees in the .gsf.
TEST_F(PsiSurfaceCliTest, AnHdf5ReaderOpensTheDatxWithTheSameValuesAndScale) {
  const std::string sim = simulate("sim", 64);
  const Json j = analyze(sim, path("a"));
  const std::string datx = path("a") + "/surface_nm.datx";
  const std::string npy = path("a") + "/surface_nm.npy";
  ASSERT_TRUE(fs::exists(datx));
  const std::string out = path("h5py.json");
  const std::string py = "/usr/bin/python3 '" + testing::source_dir() +
                         "/tests/support/read_datx_h5py.py' '" + datx + "' '" + npy + "' > '" +
                         out + "'";
  ASSERT_EQ(std::system(py.c_str()), 0) << py;
  const Json r = Json::parse(testing::slurp(out));
  EXPECT_EQ(r["rows"], 64);
  EXPECT_EQ(r["columns"], 64);
  EXPECT_EQ(r["dtype"], "float64");
  EXPECT_EQ(r["unit"], "NanoMeters");
  EXPECT_EQ(r["same_as_npy"], true);  // every height the very double of surface_nm.npy
  EXPECT_EQ(r["valid"], j["valid_pixels"]);
  EXPECT_EQ(r["resolution"].get<double>(), j["lateral_scale_m_per_px"].get<double>());
  EXPECT_EQ(r["resolution_unit"], "Meters");
  EXPECT_EQ(r["wavelength_m"].get<double>(), j["wavelength_nm"].get<double>() * 1e-9);
  EXPECT_EQ(r["no_data"].get<double>(), std::numeric_limits<double>::max());
  EXPECT_EQ(r["title"], "surface, piston and tilt removed");

  // The same heights as the .gsf Gwyddion opens, to float32's precision, so the same range.
  const psi::ScaledSurface gsf = psi::read_gsf(path("a") + "/surface_m.gsf");
  double lo = 1e300, hi = -1e300;
  for (const double v : gsf.height_nm.v)
    if (!std::isnan(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  EXPECT_NEAR(r["min"].get<double>(), lo, 1e-6 * std::fabs(lo));
  EXPECT_NEAR(r["max"].get<double>(), hi, 1e-6 * std::fabs(hi));
  EXPECT_GT(r["max"].get<double>() - r["min"].get<double>(), 10.0);  // nm: the part's figure

  // read_datx: bit for bit, as psi compare reads it.
  const psi::ScaledSurface back = psi::read_datx(datx);
  const psi::Map m = psi::read_npy(npy);
  ASSERT_EQ(back.height_nm.size(), m.size());
  for (std::size_t p = 0; p < m.size(); ++p) {
    ASSERT_EQ(std::isnan(back.height_nm.v[p]), std::isnan(m.v[p])) << p;
    if (!std::isnan(m.v[p])) {
      ASSERT_EQ(std::memcmp(&back.height_nm.v[p], &m.v[p], sizeof(double)), 0) << p;
    }
  }
  EXPECT_EQ(back.m_per_px, j["lateral_scale_m_per_px"].get<double>());
}

// psi compare of the .gsf against the .datx of one analysis: float32's rounding only; a .datx
// that is not one, truncated, or without a surface exits 2 naming the file.
TEST_F(PsiSurfaceCliTest, CompareReadsTheDatxAndRefusesABadOneNamingIt) {
  const std::string sim = simulate("sim", 64);
  analyze(sim, path("a"));
  const std::string gsf = path("a") + "/surface_m.gsf";
  const std::string datx = path("a") + "/surface_nm.datx";
  testing::CliResult r = run("psi compare '" + datx + "' '" + datx + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(Json::parse(r.out)["difference_rms_nm"], 0.0);
  r = run("psi compare '" + gsf + "' '" + datx + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  Json j = Json::parse(r.out);
  EXPECT_EQ(j["common_pixels"], j["a"]["valid_pixels"]);
  EXPECT_EQ(j["a"]["m_per_px"], j["b"]["m_per_px"]);
  EXPECT_LT(j["difference_rms_nm"].get<double>(), 1e-5);  // float32 metres against doubles
  EXPECT_GT(j["difference_rms_nm"].get<double>(), 0.0);

  std::ofstream(path("junk.datx")) << "not a surface";
  expect_refused("psi compare '" + gsf + "' '" + path("junk.datx") + "'",
                 path("junk.datx") + ": not an HDF5 file");
  const std::string whole = testing::slurp(datx);
  std::ofstream(path("cut.datx"), std::ios::binary) << whole.substr(0, whole.size() / 2);
  expect_refused("psi compare '" + path("cut.datx") + "' '" + gsf + "'",
                 path("cut.datx") + ": not an HDF5 file (or a truncated one)");
  // HDF5 without Zygo's groups: a .gsf renamed would be refused as not HDF5; this one is HDF5.
  const std::string py = "/usr/bin/python3 -c \"import h5py; h5py.File('" + path("empty.datx") +
                         "', 'w').create_group('Data')\"";
  ASSERT_EQ(std::system(py.c_str()), 0) << py;
  expect_refused("psi compare '" + gsf + "' '" + path("empty.datx") + "'",
                 path("empty.datx") + ": no group /Data/Surface");
  expect_refused("psi compare '" + gsf + "' '" + path("absent.datx") + "'",
                 path("absent.datx") + ": no such file");
  // Given to psi analyze as a frame, a .datx is named too.
  expect_refused("psi analyze '" + datx + "' '" + datx + "' '" + datx + "' '" + datx + "' --out '" +
                     path("e") + "'",
                 datx);
}

TEST_F(PsiSurfaceCliTest, CompareGivesTheDifferenceAndRefusesMapsThatDoNotMatch) {
  const std::string sim = simulate("sim", 64);
  analyze(sim, path("a"));
  analyze(sim, path("b"), "--algorithm lsq --steps-rad 0,1.5708,3.1416,4.7124,6.2832");
  const std::string a = path("a") + "/surface_m.gsf";
  const std::string b = path("b") + "/surface_m.gsf";

  // A map against itself: nothing.
  testing::CliResult r = run("psi compare '" + a + "' '" + a + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  Json j = Json::parse(r.out);
  EXPECT_EQ(j["difference_rms_nm"], 0.0);
  EXPECT_EQ(j["zernike_difference_nm"][3], 0.0);

  // Two algorithms on the same frames: within a nanometre, and the difference's terms are B's
  // minus A's.
  r = run("psi compare '" + a + "' '" + b + "' --json --out '" + path("cmp") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  j = Json::parse(r.out);
  EXPECT_GT(j["common_pixels"].get<int>(), 2000);
  EXPECT_LT(j["difference_rms_nm"].get<double>(), 1.0);
  EXPECT_EQ(j["zernike_a_nm"].size(), 37u);
  for (std::size_t k = 0; k < 37; ++k)
    EXPECT_NEAR(j["zernike_difference_nm"][k].get<double>(),
                j["zernike_b_nm"][k].get<double>() - j["zernike_a_nm"][k].get<double>(), 1e-9);
  EXPECT_TRUE(fs::exists(path("cmp") + "/difference_m.gsf"));
  EXPECT_EQ(Json::parse(testing::slurp(path("cmp") + "/comparison.json")), j);
  r = run("psi compare '" + a + "' '" + b + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("B - A over"), std::string::npos) << r.out;

  // Another lateral scale: the same frames with a 20 mm pupil.
  analyze(sim, path("c"), "--pupil-radius-m 0.02");
  expect_refused("psi compare '" + a + "' '" + path("c") + "/surface_m.gsf'",
                 "the maps' lateral scales differ: " + a);
  // Another size.
  analyze(simulate("small", 48), path("d"));
  expect_refused("psi compare '" + a + "' '" + path("d") + "/surface_m.gsf'",
                 "the maps' sizes differ: " + a + " is 64 x 64 pixels, " + path("d") +
                     "/surface_m.gsf is 48 x 48");
  // Unreadable input names the file.
  std::ofstream(path("junk.gsf")) << "not a surface";
  expect_refused("psi compare '" + a + "' '" + path("junk.gsf") + "'",
                 path("junk.gsf") + ": not a Gwyddion Simple Field file");
  expect_refused("psi compare '" + path("absent.gsf") + "' '" + a + "'", path("absent.gsf"));
  expect_refused("psi compare '" + a + "' '" + path("a") + "/surface_nm.npy'",
                 "surface_nm.npy: only Gwyddion Simple Field (.gsf) and Zygo .datx files are "
                 "compared");
  expect_refused(
      "psi analyze '" + sim + "/frame_00.png' --pupil-radius-m 0 --out '" + path("e") + "'",
      "--pupil-radius-m = 0 must be");
}

}  // namespace
}  // namespace piezoshift
