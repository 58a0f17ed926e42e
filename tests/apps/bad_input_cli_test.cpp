// Input that once reached an `internal error`, ran without bound or was accepted though
// wrong. Each case now exits 2 with a message naming its source (the option, or the file), or
// finishes; the program is run as a user would.
#include <unistd.h>

#include <filesystem>
#include <initializer_list>
#include <string>

#include <gtest/gtest.h>

#include "../support/cli_test.hpp"

namespace {

using piezoshift::testing::CliResult;

class BadInput : public piezoshift::testing::CliTest {
 protected:
  std::string dir() const { return dir_.string(); }
  // Exit status 2, no internal error, and each piece in stderr.
  void refused(const std::string& args, std::initializer_list<std::string> pieces) {
    const CliResult r = run(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    for (const std::string& p : pieces)
      EXPECT_NE(r.err.find(p), std::string::npos) << args << "\n" << r.err;
  }
};

// `--plot somedir/` was once an internal error.
TEST_F(BadInput, APlotPathThatNamesAFolderIsRefusedNamingTheOption) {
  const std::string data = write("lin.csv", "zd_um,measured_um\n0,0\n1,1.001\n2,2\n");
  refused("analyze linearity --data '" + data + "' --plot '" + dir() + "/'",
          {"--plot " + dir() + "/", "names a folder"});
}

// `--plot /proc/x.png` once exited 1 after the metrics, `--plot .` drew `..png`. A path
// that names no file, or whose folder takes no file, is refused before the data is read.
TEST_F(BadInput, APlotPathThatCannotBeWrittenIsRefusedBeforeTheData) {
  const std::string data = write("lin.csv", "zd_um,measured_um\n0,0\n1,1.001\n2,2\n");
  refused("analyze linearity --data '" + data + "' --plot /proc/x.png",
          {"--plot /proc/x.png: cannot create a file in /proc"});
  refused("analyze step --data '" + data + "' --plot /proc/self/sub/x.svg",
          {"--plot /proc/self/sub/x.svg: the folder /proc/self/sub does not exist (it is not "
           "created)"});
  refused("analyze repeatability --data missing.csv --plot /proc/x.png", {"--plot /proc/x.png"});
  // A line break in the name was once exit 1; a folder that does not exist was created.
  refused("analyze linearity --data '" + data + "' --plot '" + dir() + "/a\nb.png'",
          {"--plot " + dir() + "/a b.png: holds a control character"});
  refused("analyze linearity --data '" + data + "' --plot '" + dir() + "/new/x.png'",
          {"--plot " + dir() + "/new/x.png: the folder " + dir() + "/new does not exist"});
  refused("analyze linearity --data '" + data + "' --plot '" + data + "/x.png'",
          {"--plot " + data + "/x.png: " + data + " is not a folder"});
  refused("analyze linearity --data '" + data + "' --plot '" + dir() + "/.'",
          {"--plot " + dir() + "/.: names a folder; give a file, e.g. " + dir() + "/./figure.png"});
  refused("analyze linearity --data '" + data + "' --plot '" + dir() + "/..'",
          {"--plot " + dir() + "/..: names a folder"});
  refused("analyze linearity --data '" + data + "' --plot '" + dir() + "/.svg'",
          {"--plot " + dir() + "/.svg: has no name before .svg; give one, e.g. " + dir() +
           "/figure.svg"});
  // Nothing was drawn by the refusals.
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir_))
    ++files;
  EXPECT_EQ(files, 2u);  // lin.csv and stderr.txt
}

TEST_F(BadInput, RepeatabilityOfDataSpreadOverMicronsIsComputedAndOverflowIsRefused) {
  std::string wide = "measured_um\n";
  for (int i = 0; i <= 11; ++i)
    wide += std::to_string(i) + "\n";
  const CliResult r = run("analyze repeatability --json --data '" + write("wide.csv", wide) + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"repeatability_nm\": 3605.55"), std::string::npos) << r.out;
  const std::string huge = write("huge.csv", "measured_um\n1e308\n-1e308\n");
  refused("analyze repeatability --data '" + huge + "'", {huge + ": repeatability", "overflow"});
}

TEST_F(BadInput, LinearityThatOverflowsIsAFailureNotANan) {
  const std::string lin =
      write("lin.csv", "zd_um,measured_um\n1e308,1e308\n-1e308,-1e308\n0,1e300\n");
  refused("analyze linearity --data '" + lin + "'", {lin + ": linearity", "overflow"});
}

// An output folder that cannot be made (a file system error on a path the user gave) is bad
// input, not an internal error.
TEST_F(BadInput, AnOutputFolderThatCannotBeMadeIsBadInput) {
  refused("psi simulate --out /dev/null/x", {"/dev/null/x"});
}

TEST_F(BadInput, StepOptionsOutOfRangeNameTheOption) {
  const std::string step = write("step.csv", "t_s,measured_um\n0,0\n0.001,1\n0.002,1\n0.003,1\n");
  refused("analyze step --data '" + step + "' --median-window 18446744073709551615",
          {"--median-window", "[1, 1001]"});
  refused("analyze step --data '" + step + "' --step-time-s nan", {"--step-time-s nan"});
}

TEST_F(BadInput, DataAndConfigFilesMustBeBoundedRegularFiles) {
  refused("analyze repeatability --data /dev/zero", {"/dev/zero: is a device"});
  refused("analyze repeatability --data '" + dir() + "'", {dir() + ": is a directory"});
  refused("simulate --step-um 1 --config '" + dir() + "'", {dir() + ": is a directory"});
  refused("run --duration-s 0.01 --free-run --calibration '" + dir() + "'",
          {dir() + ": is a directory"});
  // one byte over the 64 MiB limit of a data file
  const std::string big = path("big.csv");
  ASSERT_EQ(::truncate(write("big.csv", "").c_str(), (64 << 20) + 1), 0);
  refused("analyze repeatability --data '" + big + "'",
          {big + ": 67108865 bytes is more than the limit of 67108864 bytes"});
}

TEST_F(BadInput, IntegerOptionsAreNotWrappedOrSaturated) {
  refused("simulate --step-um 1 --duration-s 0.01 --seed -1", {"--seed: -1 is not a whole number"});
  refused("run --duration-s 0.01 --free-run --max-overruns 18446744073709551616",
          {"--max-overruns: 18446744073709551616 is not a whole number in [1, 1000000]"});
}

// Command-line errors carry the program's prefix like every other error, and an option the
// command does not have gets the closest one it does.
TEST_F(BadInput, CommandLineErrorsNameTheProgramAndSuggestTheClosestOption) {
  refused("compare --seeds 9-1", {"piezoshift: error: --seeds: 9-1 is not a list of distinct"});
  refused("design --cfg x", {"piezoshift: error: ",
                             "piezoshift: --cfg is not an option of design: did you mean "
                             "--config?"});
  refused("simulate --step-un 5", {"--step-un is not an option of simulate: did you mean "
                                   "--step-um?"});
  refused("simulate --zzzzzz 5", {"--zzzzzz is not an option of simulate\n"});
  const CliResult help = run("simulate --help");
  EXPECT_NE(help.out.find("a whole number in [0, 2^64 - 1]"), std::string::npos) << help.out;
}

// `serve --camera twin --surface Z4=1e308` once ended a measurement in an uncaught
// exception; --mask was ignored with the twin camera. Both are refused before anything runs.
TEST_F(BadInput, ServesTwinSurfaceAndMaskAreCheckedBeforeItStarts) {
  refused("serve --camera twin --http-port 0 --surface Z4=1e308",
          {"--surface 'Z4=1e308': 'Z4=1e308' is beyond +-2000 nm RMS per term"});
  refused("serve --camera twin --http-port 0 --mask '" + dir() + "/m.png'",
          {"--mask: the twin camera renders its own pupil and analyses it"});
}

TEST_F(BadInput, RunTimesBeyondTheLongestRunNameTheirLimit) {
  refused("run --duration-s 1e9", {"--duration-s 1000000000: must be in (0, 1000000] s"});
  refused("run --duration-s 1 --free-run --fault sgs-open@1e10",
          {"--fault 'sgs-open@1e10'", "beyond the longest run, 1000000 s"});
}

// In-range settings that once made a procedure run for hours. Every command that runs the
// twin's procedures estimates their cost first (rig/procedure_cost.hpp) and refuses it above the
// budget, naming the settings and --max-physics-steps, before anything runs.
TEST_F(BadInput, ProceduresThatWouldRunForHoursAreRefusedBeforeTheyStart) {
  std::string cfg = write("slow.toml", "[twin.interferometer]\nstatic_average_s = 1e6\n");
  const std::initializer_list<std::string> named{"static_average_s = 1e+06", "budget of 1e+09",
                                                 "--max-physics-steps"};
  for (const char* cmd : {"calibrate --out CAL", "calibrate --controller improved --out CAL",
                          "run --daq sim --free-run --duration-s 1", "serve --daq sim --port 0",
                          "simulate --step-um 1 --duration-s 1", "reproduce --quick --out REP",
                          "compare --quick --seeds 1 --out CMP", "measure --free-run --out MEAS"}) {
    std::string args = cmd;
    for (const char* name : {"CAL", "REP", "CMP", "MEAS"})
      if (const auto at = args.find(name); at != std::string::npos)
        args.replace(at, std::string(name).size(), dir() + "/" + name);
    refused(args + " --config '" + cfg + "'", named);
  }
  // A faster physics rate multiplies the steps: 1e7 Hz at 1e-5 s ran past 25 s in `calibrate`.
  cfg = write("fast.toml", "[twin]\nphysics_rate_Hz = 1e7\n[twin.daq]\nsample_time_s = 1e-5\n");
  refused("calibrate --out " + dir() + "/c.toml --config '" + cfg + "'",
          {"physics_rate_Hz = 1e+07", "--max-physics-steps"});
  refused("calibrate --max-physics-steps 0 --out " + dir() + "/c.toml",
          {"--max-physics-steps = 0 must be in [1, 1e15]"});
}

}  // namespace
