#include "piezoshift/io/config_file.hpp"
#include "piezoshift/core/bounds.hpp"

#include <sys/stat.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/input_file.hpp"

#include "../support/temp_dir_test.hpp"

namespace piezoshift::io {
namespace {

// The message of the InputError that f throws ("" if none, which fails the test).
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no core::InputError thrown";
  return "";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(ConfigFile, ReadsEachTypeAndLeavesAbsentKeysAlone) {
  const ConfigFile f = ConfigFile::parse(
      "[s]\nx = 2.5\nn = 7\ni = -3\nflag = true\nname = \"hello\"\n", "test.toml");
  const ConfigSection s = f.section("s");
  double x = 0.0, n = 0.0, absent = 42.0;
  std::int64_t i = 0;
  bool flag = false;
  std::string name;
  EXPECT_TRUE(s.read("x", x));
  EXPECT_TRUE(s.read("n", n));  // a TOML integer is accepted where a number is wanted
  EXPECT_TRUE(s.read("i", i));
  EXPECT_TRUE(s.read("flag", flag));
  EXPECT_TRUE(s.read("name", name));
  EXPECT_FALSE(s.read("absent", absent));
  EXPECT_DOUBLE_EQ(x, 2.5);
  EXPECT_DOUBLE_EQ(n, 7.0);
  EXPECT_EQ(i, -3);
  EXPECT_TRUE(flag);
  EXPECT_EQ(name, "hello");
  EXPECT_DOUBLE_EQ(absent, 42.0);
  EXPECT_TRUE(s.has("x"));
  EXPECT_FALSE(s.has("absent"));
  EXPECT_NO_THROW(f.reject_unknown());
}

TEST(ConfigFile, AbsentSectionReadsAsEmpty) {
  const ConfigFile f = ConfigFile::parse("", "empty.toml");
  double x = 1.0;
  EXPECT_FALSE(f.section("nowhere").read("x", x));
  EXPECT_DOUBLE_EQ(x, 1.0);
  EXPECT_NO_THROW(f.reject_unknown());
}

TEST(ConfigFile, WrongTypeNamesFileLineKeyAndTypes) {
  const ConfigFile f = ConfigFile::parse("[s]\n\nx = \"fast\"\nn = 1.5\nb = 1\nv = 3\n", "t.toml");
  double x = 0.0;
  std::string m = error_of([&] { f.section("s").read("x", x); });
  EXPECT_TRUE(contains(m, "t.toml:3:")) << m;
  EXPECT_TRUE(contains(m, "s.x")) << m;
  EXPECT_TRUE(contains(m, "expected a number, found string")) << m;
  std::int64_t n = 0;
  m = error_of([&] { f.section("s").read("n", n); });
  EXPECT_TRUE(contains(m, "s.n: expected an integer")) << m;
  bool b = false;
  m = error_of([&] { f.section("s").read("b", b); });
  EXPECT_TRUE(contains(m, "s.b: expected true or false")) << m;
  std::array<double, 3> v{};
  m = error_of([&] { f.section("s").read("v", v); });
  EXPECT_TRUE(contains(m, "s.v: expected a list of three numbers")) << m;
}

TEST(ConfigFile, BoundsAreEnforcedAndDescribed) {
  const ConfigFile f =
      ConfigFile::parse("[s]\nzero = 0.0\nneg = -1\nhalf = 0.5\nok = 0.25\nbig = 11\n", "b.toml");
  const ConfigSection s = f.section("s");
  double v = 0.0;
  std::string m = error_of([&] { s.read("zero", v, core::Bounds::positive()); });
  EXPECT_TRUE(contains(m, "b.toml:2:")) << m;
  EXPECT_TRUE(contains(m, "s.zero: value 0 is not allowed: must be > 0")) << m;
  m = error_of([&] { s.read("neg", v, core::Bounds::non_negative()); });
  EXPECT_TRUE(contains(m, "must be >= 0")) << m;
  m = error_of([&] { s.read("half", v, core::Bounds::open(0.0, 0.5)); });
  EXPECT_TRUE(contains(m, "must be in (0, 0.5)")) << m;
  EXPECT_TRUE(s.read("half", v, core::Bounds::closed(0.0, 0.5)));
  EXPECT_DOUBLE_EQ(v, 0.5);
  EXPECT_TRUE(s.read("ok", v, core::Bounds::open(0.0, 0.5)));
  EXPECT_DOUBLE_EQ(v, 0.25);
  std::int64_t i = 0;
  m = error_of([&] { s.read("big", i, core::Bounds::closed(1, 10)); });
  EXPECT_TRUE(contains(m, "s.big: value 11 is not allowed: must be in [1, 10]")) << m;
  EXPECT_EQ(core::Bounds::any().describe(), "a finite number");
  const core::Bounds below3{.lo = -1e308, .hi = 3.0, .hi_open = true};
  EXPECT_EQ(below3.describe(), "< 3");
}

TEST(ConfigFile, NanAndInfinityAreRejectedEvenWithoutBounds) {
  const ConfigFile f = ConfigFile::parse("x = nan\ny = inf\nz = -inf\n", "n.toml");
  double v = 1.0;
  std::string m = error_of([&] { f.section("").read("x", v); });
  EXPECT_TRUE(contains(m, "n.toml:1:")) << m;
  EXPECT_TRUE(contains(m, "x: value nan is not allowed: not a finite number")) << m;
  EXPECT_TRUE(contains(error_of([&] { f.section("").read("y", v); }), "not a finite number"));
  EXPECT_TRUE(contains(error_of([&] { f.section("").read("z", v, core::Bounds::positive()); }),
                       "not a finite number"));
  EXPECT_DOUBLE_EQ(v, 1.0);  // untouched by the failed reads
}

TEST(ConfigFile, SyntaxErrorGivesLineAndColumn) {
  std::string m = error_of([] { ConfigFile::parse("[a]\nx = 1\ny = = 2\n", "syn.toml"); });
  EXPECT_TRUE(contains(m, "syn.toml:3:")) << m;
  EXPECT_TRUE(contains(m, "syntax error")) << m;
  m = error_of([] { ConfigFile::parse("[a]\nx = 1\nx = 2\n", "dup.toml"); });
  EXPECT_TRUE(contains(m, "dup.toml:3:")) << m;  // a key defined twice
}

TEST(ConfigFile, UnknownKeyAndUnknownSection) {
  const ConfigFile f = ConfigFile::parse("[s]\nx = 1.0\nxx = 2.0\n", "u.toml");
  double x = 0.0;
  f.section("s").read("x", x);
  std::string m = error_of([&] { f.reject_unknown(); });
  EXPECT_TRUE(contains(m, "u.toml:3:")) << m;
  EXPECT_TRUE(contains(m, "s.xx: unknown key")) << m;

  const ConfigFile g = ConfigFile::parse("[s]\nx = 1.0\n[typo]\ny = 2\n", "u2.toml");
  g.section("s").read("x", x);
  m = error_of([&] { g.reject_unknown(); });
  EXPECT_TRUE(contains(m, "typo: unknown section")) << m;

  const ConfigFile root = ConfigFile::parse("stray = 1\n", "u3.toml");
  EXPECT_TRUE(contains(error_of([&] { root.reject_unknown(); }), "stray: unknown key"));
}

// A quoted key with dots is one key of that name. Beside the setting whose path it
// spells, it once passed as that setting (its value never read, nothing said).
TEST(ConfigFile, AQuotedDottedKeyIsRefusedEvenBesideTheSettingItSpells) {
  const std::string text = "\"twin.daq.sample_time_s\" = \"x\"\n[twin.daq]\nsample_time_s = 1e-4\n";
  const ConfigFile f = ConfigFile::parse(text, "q.toml");
  double dt_s = 0.0;
  EXPECT_TRUE(f.section("twin.daq").read("sample_time_s", dt_s));
  EXPECT_DOUBLE_EQ(dt_s, 1e-4);
  std::string m = error_of([&] { f.reject_unknown(); });
  EXPECT_TRUE(contains(m, "q.toml:1:")) << m;
  EXPECT_TRUE(contains(m, "\"twin.daq.sample_time_s\": unknown key")) << m;

  // Alone, and one level down.
  const ConfigFile g = ConfigFile::parse("\"twin.daq.sample_time_s\" = 1e-4\n", "q2.toml");
  g.section("twin.daq").read("sample_time_s", dt_s);
  m = error_of([&] { g.reject_unknown(); });
  EXPECT_TRUE(contains(m, "q2.toml:1:")) << m;
  EXPECT_TRUE(contains(m, "\"twin.daq.sample_time_s\": unknown key")) << m;
  const ConfigFile h = ConfigFile::parse(
      "[twin]\nseed = 1\n\"daq.sample_time_s\" = 1e-4\n[twin.daq]\nsample_time_s = 1e-4\n",
      "q3.toml");
  std::int64_t seed = 0;
  h.section("twin").read("seed", seed);
  h.section("twin.daq").read("sample_time_s", dt_s);
  m = error_of([&] { h.reject_unknown(); });
  EXPECT_TRUE(contains(m, "q3.toml:3:")) << m;
  EXPECT_TRUE(contains(m, "twin.\"daq.sample_time_s\": unknown key")) << m;

  // A quoted table name with a dot, beside the real table.
  const ConfigFile t = ConfigFile::parse(
      "[twin.daq]\nsample_time_s = 1e-4\n[\"twin.daq\"]\nsample_time_s = 1\n", "q4.toml");
  t.section("twin.daq").read("sample_time_s", dt_s);
  m = error_of([&] { t.reject_unknown(); });
  EXPECT_TRUE(contains(m, "q4.toml:3:")) << m;
  EXPECT_TRUE(contains(m, "\"twin.daq\": unknown section")) << m;
  // Plain dotted keys (TOML's way to name nested tables) are still read.
  const ConfigFile d = ConfigFile::parse("twin.daq.sample_time_s = 2e-4\n", "q5.toml");
  EXPECT_TRUE(d.section("twin.daq").read("sample_time_s", dt_s));
  EXPECT_DOUBLE_EQ(dt_s, 2e-4);
  EXPECT_NO_THROW(d.reject_unknown());
}

TEST(ConfigFile, EmptyUnknownSectionIsStillUnknown) {
  // A misspelt section header with nothing under it yet must not pass silently.
  const ConfigFile f = ConfigFile::parse("[actuatr]\n", "e.toml");
  const std::string m = error_of([&] { f.reject_unknown(); });
  EXPECT_TRUE(contains(m, "e.toml:1:")) << m;
  EXPECT_TRUE(contains(m, "actuatr: unknown section")) << m;
  // An empty section that was asked for is fine.
  const ConfigFile g = ConfigFile::parse("[hinge]\n", "e2.toml");
  double unused = 0.0;
  g.section("hinge").read("width_m", unused);
  EXPECT_NO_THROW(g.reject_unknown());
}

TEST(ConfigFile, UnknownKeysAreReportedInFileOrder) {
  // toml++ iterates keys alphabetically; the first offender in the file must be named.
  const ConfigFile f = ConfigFile::parse("[s]\nzeta = 1\nalpha = 2\n", "o.toml");
  f.section("s");
  const std::string m = error_of([&] { f.reject_unknown(); });
  EXPECT_TRUE(contains(m, "o.toml:2:")) << m;
  EXPECT_TRUE(contains(m, "s.zeta")) << m;
}

TEST(ConfigFile, NestedSections) {
  const ConfigFile f = ConfigFile::parse(
      "[twin]\nseed = 7\n[twin.amplifier]\ngain = 15.0\n[twin.amplifier.extra]\nq = 1\n",
      "nest.toml");
  std::int64_t seed = 0;
  double gain = 0.0;
  EXPECT_TRUE(f.section("twin").read("seed", seed));
  EXPECT_TRUE(f.section("twin.amplifier").read("gain", gain));
  EXPECT_EQ(seed, 7);
  EXPECT_DOUBLE_EQ(gain, 15.0);
  std::string m = error_of([&] { f.reject_unknown(); });
  EXPECT_TRUE(contains(m, "twin.amplifier.extra: unknown section")) << m;

  // Asking only for the inner table makes its parents known, but not their own keys.
  const ConfigFile g = ConfigFile::parse("[a]\nk = 1\n[a.b]\nv = 2.0\n", "nest2.toml");
  double v = 0.0;
  g.section("a.b").read("v", v);
  EXPECT_DOUBLE_EQ(v, 2.0);
  m = error_of([&] { g.reject_unknown(); });
  EXPECT_TRUE(contains(m, "a.k: unknown key")) << m;

  // A dotted name that runs into a plain value is not a section.
  const ConfigFile h = ConfigFile::parse("a = 1\n", "nest3.toml");
  EXPECT_TRUE(contains(error_of([&] { h.section("a"); }), "a: expected a section"));
}

TEST(ConfigFile, ThreeVectors) {
  const ConfigFile f = ConfigFile::parse(
      "[k]\nv = [1, 2.5, -3]\nshort = [1.0, 2.0]\nbad = [1.0, \"x\", 3.0]\npos = [1.0, 0.0, 2.0]\n",
      "v.toml");
  const ConfigSection k = f.section("k");
  std::array<double, 3> v{};
  EXPECT_TRUE(k.read("v", v));
  EXPECT_DOUBLE_EQ(v[0], 1.0);
  EXPECT_DOUBLE_EQ(v[1], 2.5);
  EXPECT_DOUBLE_EQ(v[2], -3.0);
  EXPECT_TRUE(contains(error_of([&] { k.read("short", v); }), "k.short: expected a list of three"));
  std::string m = error_of([&] { k.read("bad", v); });
  EXPECT_TRUE(contains(m, "k.bad[1]: expected a number, found string")) << m;
  m = error_of([&] { k.read("pos", v, core::Bounds::positive()); });
  EXPECT_TRUE(contains(m, "k.pos[1]: value 0 is not allowed: must be > 0")) << m;
  EXPECT_DOUBLE_EQ(v[1], 2.5);  // a failed read leaves the whole vector alone
}

TEST(ConfigFile, ThreeByThreeMatrices) {
  // The paper's motion transmission matrix A (Section 4.1).
  const ConfigFile f = ConfigFile::parse(
      "[c]\n"
      "A = [[-0.4218, 0.6030, 0.6547], [0.3482, -0.1491, 0.6962], [0.6321, 0.4397, -0.2980]]\n"
      "two_rows = [[1, 0, 0], [0, 1, 0]]\n"
      "ragged = [[1, 0, 0], [0, 1], [0, 0, 1]]\n"
      "nan_inside = [[1, 0, 0], [0, 1, 0], [0, nan, 1]]\n",
      "m.toml");
  const ConfigSection c = f.section("c");
  std::array<std::array<double, 3>, 3> a{};
  EXPECT_TRUE(c.read("A", a));
  EXPECT_DOUBLE_EQ(a[0][0], -0.4218);
  EXPECT_DOUBLE_EQ(a[1][2], 0.6962);
  EXPECT_DOUBLE_EQ(a[2][1], 0.4397);
  EXPECT_TRUE(
      contains(error_of([&] { c.read("two_rows", a); }), "c.two_rows: expected three rows"));
  EXPECT_TRUE(contains(error_of([&] { c.read("ragged", a); }), "row 2 is not three numbers"));
  std::string m = error_of([&] { c.read("nan_inside", a); });
  EXPECT_TRUE(contains(m, "c.nan_inside[2][1]: value nan")) << m;
  EXPECT_DOUBLE_EQ(a[0][0], -0.4218);  // untouched by the failed reads
  EXPECT_NO_THROW(f.reject_unknown());
}

using ConfigFileOnDisk = piezoshift::testing::TempDirTest;

TEST_F(ConfigFileOnDisk, LoadsAFileAndNamesItInErrors) {
  const std::string path = write("good.toml", "[s]\nx = 3.0\n");
  const ConfigFile f = ConfigFile::load(path);
  EXPECT_EQ(f.source(), path);
  double x = 0.0;
  EXPECT_TRUE(f.section("s").read("x", x));
  EXPECT_DOUBLE_EQ(x, 3.0);

  const std::string bad = write("bad.toml", "[s]\nx = 3.0\ny = [1, 2\n");
  const std::string m = error_of([&] { ConfigFile::load(bad); });
  EXPECT_TRUE(contains(m, bad + ":")) << m;
  EXPECT_TRUE(contains(m, "syntax error")) << m;
}

TEST_F(ConfigFileOnDisk, MissingFileIsAnInputError) {
  const std::string path = (dir_ / "nope.toml").string();
  const std::string m = error_of([&] { ConfigFile::load(path); });
  EXPECT_TRUE(contains(m, path)) << m;
  EXPECT_TRUE(contains(m, "cannot open: No such file or directory")) << m;
}

// A directory once read as an empty file (every key silently defaulted), a FIFO blocked or
// streamed without end; both are refused at once, and so is a file above the limit.
TEST_F(ConfigFileOnDisk, OnlyABoundedRegularFileIsRead) {
  std::string m = error_of([&] { ConfigFile::load(dir_.string()); });
  EXPECT_TRUE(contains(m, dir_.string() + ": is a directory; expected a regular file")) << m;
  const std::string fifo = (dir_ / "pipe.toml").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  m = error_of([&] { ConfigFile::load(fifo); });
  EXPECT_TRUE(contains(m, fifo + ": is a FIFO (pipe); expected a regular file")) << m;
  const std::string big = (dir_ / "big.toml").string();
  std::ofstream(big) << std::string(kMaxConfigFileBytes + 1, '#');
  m = error_of([&] { ConfigFile::load(big); });
  EXPECT_TRUE(contains(m, "1048577 bytes is more than the limit of 1048576 bytes")) << m;
  EXPECT_EQ(read_input_file(big, kMaxConfigFileBytes + 1).size(), kMaxConfigFileBytes + 1);
}

}  // namespace
}  // namespace piezoshift::io
