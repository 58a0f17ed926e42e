// `piezoshift measure` end to end (docs/measure.md): the stage stepped through the shipping loop,
// the camera exposed once it settled, the surface found again; and every failure a clear exit
// status with nothing half-written.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

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

// RMS of a - b over the pixels finite in both, after removing their mean difference.
double rms_difference(const psi::Map& a, const psi::Map& b) {
  double s = 0.0, s2 = 0.0;
  std::size_t n = 0;
  for (std::size_t p = 0; p < a.size(); ++p)
    if (std::isfinite(a.v[p]) && std::isfinite(b.v[p])) {
      const double d = a.v[p] - b.v[p];
      s += d;
      s2 += d * d;
      ++n;
    }
  return n ? std::sqrt(std::max(0.0, s2 / n - (s / n) * (s / n))) : INFINITY;
}

// The column of a CSV file with a header line, as numbers.
std::vector<double> csv_column(const std::string& file, const std::string& name) {
  std::ifstream in(file);
  std::string line, cell;
  std::getline(in, line);
  std::istringstream header(line);
  int column = -1;
  for (int c = 0; std::getline(header, cell, ','); ++c)
    if (cell == name)
      column = c;
  std::vector<double> values;
  while (column >= 0 && std::getline(in, line)) {
    std::istringstream row(line);
    for (int c = 0; c <= column; ++c)
      std::getline(row, cell, ',');
    values.push_back(std::stod(cell));
  }
  return values;
}

class MeasureCli : public testing::CliTest {
 protected:
  // A 96 x 96 camera: quick under the sanitizers, fringes enough for the analysis.
  std::string small_camera(const std::string& format = "Mono12") {
    return write("cam.toml",
                 "[camera]\nwidth_px = 96\nheight_px = 96\npixel_format = \"" + format + "\"\n");
  }
  Json measure(const std::string& args, int expected_status = 0) {
    const testing::CliResult r = run("measure --free-run --json " + args);
    EXPECT_EQ(r.status, expected_status) << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    return r.out.empty() ? Json() : Json::parse(r.out, nullptr, false);
  }
  // The improved controller calibrated on the twin, and a 96 px camera with the cavity's drift in
  // the fringes: the options of a measurement with both.
  std::string improved_with_drift() {
    const testing::CliResult cal =
        run("calibrate --controller improved --out '" + path("cal/improved.toml") + "'");
    EXPECT_EQ(cal.status, 0) << cal.err;
    const std::string cfg = write("drift.toml",
                                  "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                  "[twin.cavity]\nin_fringes = true\n");
    return "--calibration '" + path("cal/improved.toml") + "' --config '" + cfg + "' ";
  }
  void refused(const std::string& args, const std::string& piece) {
    const testing::CliResult r = run("measure --free-run " + args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(piece), std::string::npos) << args << "\n" << r.err;
  }
};

// The twin camera on the twin with the paper's controller (the start-up calibration): every file,
// the truth beside the surface, the frames re-analysed as recorded by the files camera.
TEST_F(MeasureCli, TwinMeasurementWritesEverythingAndItsFramesReplay) {
  const std::string cam = small_camera();
  const Json j = measure("--config '" + cam + "' --out '" + path("m") + "'");
  for (const char* f : {"frames/frame_a1_00.png", "frames/frame_a1_04.png", "mask.png",
                        "surface_nm.npy", "surface_m.gsf", "surface_m_mask.gsf", "surface_nm.datx",
                        "surface_truth_nm.npy", "exposures.csv", "measurement.json", "report.md"})
    EXPECT_TRUE(fs::exists(path("m") + "/" + f)) << f;
  // The .gsf: the .npy's surface in float32 metres, its pixels without a value masked, and the
  // lateral scale the JSON states (the twin's 25 mm pupil over its radius in pixels).
  const psi::ScaledSurface gsf = psi::read_gsf(path("m") + "/surface_m.gsf");
  const psi::Map npy = psi::read_npy(path("m") + "/surface_nm.npy");
  EXPECT_EQ(gsf.m_per_px, j["lateral_scale_m_per_px"].get<double>());
  EXPECT_GT(gsf.m_per_px, 0.025 / 48);  // a pupil of 40 to 48 px radius in the 96 px frame
  EXPECT_LT(gsf.m_per_px, 0.025 / 40);
  ASSERT_EQ(gsf.height_nm.size(), npy.size());
  for (std::size_t p = 0; p < npy.size(); ++p) {
    ASSERT_EQ(std::isfinite(gsf.height_nm.v[p]), std::isfinite(npy.v[p])) << p;
    if (std::isfinite(npy.v[p])) {
      ASSERT_EQ(gsf.height_nm.v[p], static_cast<float>(npy.v[p] * 1e-9) * 1e9) << p;
    }
  }
  // The .datx: the .npy's doubles bit for bit and the same scale, read by read_datx (as psi
  // compare does) and by h5py as prysm reads it.
  const psi::ScaledSurface datx = psi::read_datx(path("m") + "/surface_nm.datx");
  EXPECT_EQ(datx.m_per_px, gsf.m_per_px);
  ASSERT_EQ(datx.height_nm.size(), npy.size());
  for (std::size_t p = 0; p < npy.size(); ++p) {
    ASSERT_EQ(std::isnan(datx.height_nm.v[p]), std::isnan(npy.v[p])) << p;
    if (!std::isnan(npy.v[p])) {
      ASSERT_EQ(std::memcmp(&datx.height_nm.v[p], &npy.v[p], sizeof(double)), 0) << p;
    }
  }
  const std::string py = "/usr/bin/python3 '" + testing::source_dir() +
                         "/tests/support/read_datx_h5py.py' '" + path("m") + "/surface_nm.datx' '" +
                         path("m") + "/surface_nm.npy' > '" + path("h5py.json") + "'";
  ASSERT_EQ(std::system(py.c_str()), 0) << py;
  const Json h5 = Json::parse(testing::slurp(path("h5py.json")));
  EXPECT_EQ(h5["same_as_npy"], true);
  EXPECT_EQ(h5["resolution"].get<double>(), j["lateral_scale_m_per_px"].get<double>());
  EXPECT_EQ(h5["unit"], "NanoMeters");
  EXPECT_EQ(j["frames"], 5);
  EXPECT_EQ(j["exposures"].size(), 5u);
  EXPECT_TRUE(j["converged"].get<bool>());
  // Against the truth: the camera's noise on 96 x 96 pixels and the stage's steps.
  EXPECT_LT(j["error_rms_nm"].get<double>(), 1.0);
  EXPECT_LT(j["step_error_max_mrad"].get<double>(), 20.0);
  // The same frames replayed from the files: the same surface, bit for bit in the analysis.
  const Json k = measure("--config '" + cam + "' --camera 'files:" + path("m") +
                         "/frames' --mask '" + path("m") + "/mask.png' --out '" + path("f") + "'");
  EXPECT_EQ(k["camera"], "files:" + path("m") + "/frames");
  EXPECT_LT(rms_difference(psi::read_npy(path("m") + "/surface_nm.npy"),
                           psi::read_npy(path("f") + "/surface_nm.npy")),
            1e-9);
}

// The steps are a check on the stage, not part of the surface: where AIA cannot recover them (a
// pure defocus spanning 2.75 rad: its step conditioning 0.040 is below 0.05, psi's own check),
// the measurement stands and says why the steps are missing, never a number.
TEST_F(MeasureCli, StepsThatCannotBeRecoveredAreSaidNotInvented) {
  const Json j = measure("--config '" + small_camera() + "' --surface Z4=40,rough=0 --out '" +
                         path("m") + "'");
  EXPECT_TRUE(j["converged"].get<bool>());
  EXPECT_LT(j["error_rms_nm"].get<double>(), 1.0);
  EXPECT_TRUE(j["step_error_max_mrad"].is_null());
  EXPECT_NE(j["steps_reason"].get<std::string>().find("spans too little of a fringe"),
            std::string::npos)
      << j["steps_reason"];
  EXPECT_TRUE(j["recovered_steps_rad"][0].empty());
}

TEST_F(MeasureCli, BadInputIsRefusedBeforeAnythingRuns) {
  refused("--out '" + path("x") + "' --camera webcam", "webcam");
  refused("--out '" + path("x") + "' --daq comedi:/dev/comedi9", "--camera twin");
  refused("--out '" + path("x") + "' --steps-rad 0,1,2,3,4", "unequal steps need lsq");
  refused("--out '" + path("x") + "' --algorithm lsq --steps-rad 0,1", "3 to 64 frames");
  refused("--out '" + path("x") + "' --base-um 11.4", "beyond the calibrated travel");
  refused("--out '" + path("x") + "' --camera files:" + path("none"), path("none"));
  // --mask was once ignored with the twin camera; a surface of 1e308 nm was an internal error.
  refused("--out '" + path("x") + "' --mask '" + path("m.png") + "'",
          "--mask: the twin camera renders its own pupil and analyses it");
  refused("--out '" + path("x") + "' --surface Z4=1e308",
          "--surface 'Z4=1e308': 'Z4=1e308' is beyond +-2000 nm RMS per term");
  write("full/keep.txt", "");
  fs::create_directories(path("full"));
  write("full/keep.txt", "data");
  refused("--out '" + path("full") + "'", "not an empty folder");
  EXPECT_TRUE(fs::exists(path("full/keep.txt")));
}

// A 2048 px camera took 350 MB an average, 35 GB at the 100 allowed. The memory bound
// refuses it before the loop starts, naming the options and what fits.
TEST_F(MeasureCli, AMeasurementBeyondTheMemoryBoundIsRefusedBeforeItStarts) {
  const std::string big = write("big.toml", "[camera]\nwidth_px = 2048\nheight_px = 2048\n");
  const testing::CliResult r =
      run("measure --free-run --out '" + path("m") + "' --config '" + big + "' --averages 100");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--averages and --algorithm (--steps-rad) with [camera] width_px, "
                       "height_px: 100 averages x 5 frames of 2048 x 2048 px"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("at most 2 averages on this camera"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("m")));
}

// The fringe lock on the twin with the cavity's drift in the fringes: the first average is the
// reference, every later frame is locked, and the cavity's path stays nearer its set point than
// on the gauges alone (same seed). Measured on this camera: 2.6 nm RMS unlocked (the drift over
// the run and each step's error the calibration left), 1.6 nm locked; the rest is each frame's
// own settling scatter (the 2 nm settle band), which a lock one frame late cannot remove. A lock
// that did nothing would give the unlocked figure; 0.8 x leaves the seed's noise a margin.
TEST_F(MeasureCli, TheFringeLockHoldsTheDriftingCavityNearerItsSetPoint) {
  const std::string cfg = write("drift.toml",
                                "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                "[twin.cavity]\nin_fringes = true\n");
  const Json off = measure("--config '" + cfg + "' --averages 10 --out '" + path("off") + "'");
  const Json on = measure("--config '" + cfg + "' --averages 10 --lock --out '" + path("on") + "'");
  ASSERT_TRUE(off.is_object() && on.is_object());
  EXPECT_TRUE(off["lock"].is_null());
  const Json& lock = on["lock"];
  EXPECT_EQ(lock["reference_frames"], 5);
  EXPECT_EQ(lock["locked_frames"], 45);
  EXPECT_EQ(lock["holding_frames"], 0);
  EXPECT_TRUE(lock["first_refusal"].is_null()) << lock.dump();
  EXPECT_EQ(on["exposures"][0]["lock_state"], "reference");
  EXPECT_EQ(on["exposures"][5]["lock_state"], "locked");
  const double unlocked = off["path_error_rms_nm"], locked = on["path_error_rms_nm"];
  EXPECT_GT(unlocked, 1.0);  // the drift is there to hold
  EXPECT_LT(locked, 0.8 * unlocked) << locked << " vs " << unlocked;
  // Refused before anything runs: steps the reference cannot be taken from.
  refused("--lock --algorithm lsq --steps-rad 0,1,2,3 --out '" + path("x") + "'", "--lock");
}

// On a real-time clock (the twin paced by the wall clock, as on hardware) the lock's fit runs on
// a thread of its own while the loop holds the stage (instrument/fit_thread.hpp); the next move
// takes the frame's correction, as off a real-time clock. Every frame after the reference locks,
// and the hold returns to frame 0's cavity: the semi-closed loop alone brings the plate back 1
// to 3 nm off it (measured on this clock, the paper's controller, 1 s hold: -2.2 and -2.4 nm
// over the hold's second half, against -0.20 and -0.12 nm locked). Real time is not repeatable
// to the digit and its overruns are the machine's (the twin never trips on them): what is
// asserted is what the lock must do on any run and machine, the states and that offset removed;
// the hold's RMS (0.5 to 0.6 nm at full speed) grows where the fit is slower, and is not.
TEST_F(MeasureCli, TheLockRunsOnARealTimeClockWithItsFitBesideTheLoop) {
  const std::string cfg = write("drift.toml",
                                "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                "[twin.cavity]\nin_fringes = true\n");
  const testing::CliResult r = run("measure --json --config '" + cfg +
                                   "' --averages 4 --hold-s 1 --lock --out '" + path("rt") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json on = Json::parse(r.out, nullptr, false);
  ASSERT_TRUE(on.is_object());
  EXPECT_EQ(on["clock"], "realtime");
  const Json& lock = on["lock"];
  EXPECT_EQ(lock["reference_frames"], 5);
  const int hold_frames = on["hold"]["frames"];
  // 1 s: a frame every 14 ms at full speed (71); fewer where the fit is slower than the readout,
  // each move waiting for it (under the sanitizers: 27)
  EXPECT_GE(hold_frames, 10);
  EXPECT_EQ(lock["locked_frames"].get<int>(), 15 + hold_frames);
  EXPECT_EQ(lock["holding_frames"], 0);
  EXPECT_EQ(on["exposures"][19]["lock_state"], "locked");
  EXPECT_EQ(on["hold"]["lock_states"]["locked"], hold_frames);
  const std::vector<double> e = csv_column(path("rt") + "/hold.csv", "path_error_nm");
  ASSERT_EQ(e.size(), static_cast<std::size_t>(hold_frames));
  double mean = 0.0;
  for (std::size_t k = e.size() / 2; k < e.size(); ++k)
    mean += e[k] / static_cast<double>(e.size() - e.size() / 2);
  EXPECT_LT(std::fabs(mean), 0.5);
}

// `[controller] outer = "fringes"`: a calibration file that asks for the fringe lock
// locks `measure` exactly as --lock does (same seed: the same numbers, bit for bit), its
// [fringe_lock] reaches the lock, and the commands that run no lock refuse the file by name.
TEST_F(MeasureCli, ACalibrationThatAsksForTheFringeLockLocksAsTheFlagDoes) {
  const testing::CliResult cal = run("calibrate --out '" + path("paper.toml") + "'");
  ASSERT_EQ(cal.status, 0) << cal.err;
  std::ifstream in(path("paper.toml"));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto with_outer = [&](const std::string& name, const std::string& lock_section) {
    std::string t = text;
    t.replace(t.find("[controller]\n"), 13, "[controller]\nouter = \"fringes\"\n");
    return write(name, t + lock_section);
  };
  const std::string outer = with_outer("outer.toml", "");
  const std::string slow = with_outer("slow.toml", "\n[fringe_lock]\ngain_per_frame = 0.25\n");
  const std::string cfg = write("drift.toml",
                                "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                "[twin.cavity]\nin_fringes = true\n");
  const std::string common = "--config '" + cfg + "' --averages 10 ";
  const Json flag = measure(common + "--calibration '" + path("paper.toml") + "' --lock --out '" +
                            path("flag") + "'");
  const Json file = measure(common + "--calibration '" + outer + "' --out '" + path("file") + "'");
  const Json gain = measure(common + "--calibration '" + slow + "' --out '" + path("gain") + "'");
  ASSERT_TRUE(flag.is_object() && file.is_object() && gain.is_object());
  EXPECT_EQ(file["lock"], flag["lock"]);
  EXPECT_EQ(file["path_error_rms_nm"], flag["path_error_rms_nm"]);
  EXPECT_EQ(file["error_rms_nm"], flag["error_rms_nm"]);
  EXPECT_EQ(flag["lock"]["gain_per_frame"], 0.5);
  EXPECT_EQ(gain["lock"]["gain_per_frame"], 0.25);
  EXPECT_EQ(gain["lock"]["locked_frames"], 45);
  // Another gain corrects each frame by another amount: another path.
  EXPECT_NE(gain["path_error_rms_nm"], flag["path_error_rms_nm"]);
  for (const char* command : {"run --duration-s 0.1", "serve", "simulate --step-um 1"}) {
    const testing::CliResult r = run(std::string(command) + " --calibration '" + outer + "'");
    EXPECT_EQ(r.status, 2) << command << "\n" << r.err;
    EXPECT_NE(r.err.find("outer = \"fringes\""), std::string::npos) << command << "\n" << r.err;
  }
}

// The fringes washed out mid-sequence (the twin camera's fringe loss, 60 ms from
// 0.45 s: within the second average) lose the measurement no frame. Each frame without fringes is
// taken again until they come back; the lock holds its correction meanwhile and locks again
// without a jump; every frame kept has its fringes, so the surface is as good as without the loss
// (same seed, 96 px: measured 0.272 against 0.298 nm; the retaken frames' noise differs). Fringes
// that do not come back within
// --lock-retake-s end the measurement (exit 4), never a surface from frames without fringes.
TEST_F(MeasureCli, FringesLostMidSequenceAreTakenAgainAndNoFrameIsLost) {
  const std::string clear = small_camera();
  const std::string lossy = write("loss.toml",
                                  "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                  "fringe_loss_start_s = 0.45\nfringe_loss_s = 0.06\n");
  const Json base =
      measure("--config '" + clear + "' --averages 4 --lock --out '" + path("clear") + "'");
  const Json j =
      measure("--config '" + lossy + "' --averages 4 --lock --out '" + path("loss") + "'");
  ASSERT_TRUE(base.is_object() && j.is_object());
  const Json& lock = j["lock"];
  EXPECT_GE(lock["retaken_frames"].get<int>(), 2) << lock.dump();
  EXPECT_EQ(base["lock"]["retaken_frames"], 0);
  ASSERT_EQ(j["exposures"].size(), 20u);  // 4 x 5 frames, none lost
  int retaken = 0;
  for (std::size_t i = 5; i < 20; ++i) {
    EXPECT_EQ(j["exposures"][i]["lock_state"], "locked") << i;  // every kept frame has fringes
    retaken += j["exposures"][i]["retakes"].get<int>();
  }
  EXPECT_EQ(retaken, lock["retaken_frames"].get<int>());
  EXPECT_LT(j["error_rms_nm"].get<double>(), 1.1 * base["error_rms_nm"].get<double>());
  // The loss outlasts the retake time: a failure, and nothing written.
  const std::string long_loss = write("long.toml",
                                      "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                      "fringe_loss_start_s = 0.45\nfringe_loss_s = 5\n");
  const testing::CliResult r =
      run("measure --free-run --config '" + long_loss +
          "' --averages 4 --lock --lock-retake-s 0.2 --out '" + path("long") + "'");
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_NE(r.err.find("did not come back within 0.2 s"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("long")));
  refused("--lock --lock-retake-s 0 --out '" + path("x") + "'", "retake");
}

// With the lab's drift in the fringes, the lock at most halves what the stage adds to
// the surface error (improved controller, 20 averages, 96 px), the median over seeds 1 to 8 as
// the done-when asks, each seed calibrated on its own. What the stage adds is sqrt(error^2 -
// floor^2), the floor the whole measurement from an ideal stage with every frame's own noise
// draws (floor_error_rms_nm). One seed alone does not decide it: locked, the stage adds 0.01 to
// 0.04 nm to a floor of 0.119 nm, so a change of 0.007 nm in a seed's error moves its ratio from
// 0.12 to 0.57 (seed 1 after the large moves at the slew limit, which changed the move to
// the base; seeds 2 to 5 stayed at 0.15 to 0.38). Measured: docs/fizeau.md.
TEST_F(MeasureCli, TheLockHalvesWhatTheDriftingStageAddsToTheSurface) {
  const std::string cfg = write("drift.toml",
                                "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                "[twin.cavity]\nin_fringes = true\n");
  std::vector<double> ratio, off_nm, on_nm;
  for (int seed = 1; seed <= 8; ++seed) {
    const std::string seed_s = std::to_string(seed);
    const std::string cal = path("cal" + seed_s + ".toml");
    const testing::CliResult c =
        run("calibrate --controller improved --seed " + seed_s + " --out '" + cal + "'");
    ASSERT_EQ(c.status, 0) << c.err;
    const std::string common =
        "--calibration '" + cal + "' --config '" + cfg + "' --seed " + seed_s + " --averages 20 ";
    const Json off = measure(common + "--out '" + path("off" + seed_s) + "'");
    const Json on = measure(common + "--lock --out '" + path("on" + seed_s) + "'");
    ASSERT_TRUE(off.is_object() && on.is_object());
    const double floor_off = off["floor_error_rms_nm"], floor_on = on["floor_error_rms_nm"];
    // The same frame draws when no frame was taken again: the same floor.
    EXPECT_EQ(on["lock"]["retaken_frames"], 0);
    EXPECT_NEAR(floor_on, floor_off, 1e-12);
    EXPECT_NEAR(off["stage_error_rms_nm"].get<double>(),
                std::sqrt(std::pow(off["error_rms_nm"].get<double>(), 2) - floor_off * floor_off),
                1e-12);
    const double stage_off = off["stage_error_rms_nm"], stage_on = on["stage_error_rms_nm"];
    EXPECT_GT(stage_off, 0.0);
    off_nm.push_back(stage_off);
    on_nm.push_back(stage_on);
    ratio.push_back(stage_on / stage_off);
    std::printf("seed %d: the stage adds %.4f nm unlocked, %.4f nm locked (%.2f)\n", seed,
                stage_off, stage_on, stage_on / stage_off);
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  std::printf("medians: %.4f nm unlocked, %.4f nm locked; ratio %.2f\n", median(off_nm),
              median(on_nm), median(ratio));
  EXPECT_LE(median(on_nm), 0.5 * median(off_nm));
  EXPECT_LE(median(ratio), 0.5);
}

// The fringe lock's hold: after the measurement the stage stays at frame 0 for a minute of loop
// time while the camera exposes frame after frame (4286 frames), with the cavity's drift in the
// fringes, the improved controller, seed 1. On the gauges alone the cavity's path is 2.04 nm RMS
// from frame 0's (the return to frame 0 and the drift, which no gauge sees); the lock holds it
// within 0.2 nm RMS of its set point (measured 0.177 nm), the lock's bound. The paper's
// controller cannot be held so close frame by frame: its own jitter from one 1 ms exposure to
// the next is above the bound (0.54 nm locked; docs/fizeau.md).
TEST_F(MeasureCli, TheLockHoldsTheCavityWithinAFifthOfANanometreOverAMinute) {
  const std::string common = improved_with_drift() + "--hold-s 60 ";
  const Json off = measure(common + "--out '" + path("off") + "'");
  const Json on = measure(common + "--lock --out '" + path("on") + "'");
  ASSERT_TRUE(off.is_object() && on.is_object());
  const Json &h_off = off["hold"], &h_on = on["hold"];
  EXPECT_GE(h_on["span_s"].get<double>(), 59.9);
  EXPECT_GT(h_on["frames"].get<int>(), 2000);  // the camera's rate: ~19 ms a frame
  EXPECT_EQ(h_on["lock_states"]["locked"], h_on["frames"]);
  const double unlocked = h_off["path_error_rms_nm"], locked = h_on["path_error_rms_nm"];
  EXPECT_LT(locked, 0.2) << locked;
  EXPECT_GT(unlocked, 5.0 * locked) << unlocked;
  EXPECT_LT(h_on["path_error_1s_means_rms_nm"].get<double>(), 0.1);  // measured 0.057
  EXPECT_TRUE(fs::exists(path("on") + "/hold.csv"));
}

// A step that never settles, or a frame that never arrives, is not a measurement: exit 4 and no
// folder at all.
TEST_F(MeasureCli, AFailedSequenceWritesNothing) {
  const std::string cam = small_camera();
  measure("--config '" + cam + "' --settle-band-nm 1e-6 --settle-timeout-s 0.05 --out '" +
              path("a") + "'",
          4);
  EXPECT_FALSE(fs::exists(path("a")));
  measure("--config '" + cam + "' --frame-timeout-s 1e-6 --out '" + path("b") + "'", 4);
  EXPECT_FALSE(fs::exists(path("b")));
}

// measure's acceptance figures: with the improved controller on the default stage and camera, the
// twin's surface within 0.5 nm RMS and the steps from the fringes within 5 mrad of the stage's true
// steps; the measurement within 1.5 x its floor. One measurement's camera noise alone is 0.529 nm
// RMS on this camera (the same frames from an ideal stage: ideal_error_rms_nm), so 4 averages.
TEST_F(MeasureCli, ImprovedControllerRecoversTheSurfaceAndTheSteps) {
  const testing::CliResult cal =
      run("calibrate --controller improved --out '" + path("cal/improved.toml") + "'");
  ASSERT_EQ(cal.status, 0) << cal.err;
  const Json j = measure("--calibration '" + path("cal/improved.toml") + "' --averages 4 --out '" +
                         path("m") + "'");
  EXPECT_LT(j["error_rms_nm"].get<double>(), 0.5);
  EXPECT_NEAR(j["error_rms_nm"].get<double>(), 0.272, 0.02);  // measured: 0.2725
  EXPECT_NEAR(j["ideal_error_rms_nm"].get<double>(), 0.529, 0.02);
  EXPECT_LT(j["step_error_max_mrad"].get<double>(), 5.0);
  const Json& t = j["timing"];
  EXPECT_LE(t["loop_time_s"].get<double>(), 1.5 * t["floor_s"].get<double>());
  EXPECT_EQ(t["overruns"], 0);  // a simulated clock is never late
}

// The line trigger: the loop's tick raises the twin's trigger line, whose recorded edge
// triggers the twin camera. Both triggers start each exposure at the scheduled time of the tick
// after the one the stage settled on (software: camera.trigger(ticks x T) between the ticks;
// line: the next tick's edge), and the camera sees the same poses, so the same frames: measured,
// byte-equal frames, 0 nm between the surfaces and 0 s between the trigger times; the tolerances
// below are the doubles' rounding. A trigger one tick late would miss the times by 1 ms.
TEST_F(MeasureCli, LineTriggerGivesTheSoftwareTriggersSurfaceOnTickBoundaries) {
  const std::string cam = small_camera();
  const Json sw = measure("--config '" + cam + "' --out '" + path("sw") + "'");
  const Json line = measure("--config '" + cam + "' --trigger line --out '" + path("line") + "'");
  EXPECT_EQ(sw["trigger"], "software");
  EXPECT_EQ(line["trigger"], "line");
  EXPECT_LT(rms_difference(psi::read_npy(path("sw") + "/surface_nm.npy"),
                           psi::read_npy(path("line") + "/surface_nm.npy")),
            1e-9);
  EXPECT_NEAR(line["error_rms_nm"].get<double>(), sw["error_rms_nm"].get<double>(), 1e-9);
  const std::vector<double> t_sw = csv_column(path("sw") + "/exposures.csv", "trigger_time_s");
  const std::vector<double> t_line = csv_column(path("line") + "/exposures.csv", "trigger_time_s");
  ASSERT_EQ(t_line.size(), 5u);
  ASSERT_EQ(t_sw.size(), t_line.size());
  for (std::size_t k = 0; k < t_line.size(); ++k) {
    EXPECT_NEAR(t_line[k], t_sw[k], 1e-9) << "frame " << k;
    // 1 kHz: a whole number of milliseconds (the CSV's 6 decimals hold them exactly).
    EXPECT_NEAR(t_line[k] * 1000.0, std::round(t_line[k] * 1000.0), 1e-6) << t_line[k];
    if (k > 0) {
      EXPECT_GT(t_line[k], t_line[k - 1]);
    }
  }
  EXPECT_GT(t_line[0], 0.2) << "after the initial settle";
}

TEST_F(MeasureCli, LineTriggerNeedsADaqWithATriggerLine) {
  refused("--daq comedi:/dev/comedi9 --trigger line --out '" + path("c") + "'",
          "--trigger line: DAQ comedi:/dev/comedi9 has no trigger line");
  refused("--trigger sideways --out '" + path("s") + "'", "--trigger 'sideways'");
  refused("--trigger-line 2/0 --trigger line --out '" + path("t") + "'", "--trigger-line");
  refused("--camera files:nowhere --daq comedi --trigger line --trigger-line 2/x --out '" +
              path("u") + "'",
          "--trigger-line '2/x'");
  EXPECT_FALSE(fs::exists(path("c")));
}

// Aravis's in-process fake camera shown the twin's fringes (Mono16: the fake has no Mono12): the
// whole aravis: path must give the twin camera's surface.
TEST_F(MeasureCli, AravisFakeCameraFedTheTwinGivesTheTwinsSurface) {
  const std::string cam = small_camera("Mono16");
  measure("--config '" + cam + "' --out '" + path("twin") + "'");
  const Json j =
      measure("--config '" + cam + "' --camera aravis:Fake_1 --out '" + path("arv") + "'");
  EXPECT_EQ(j["camera"], "aravis:Fake_1");
  EXPECT_LT(rms_difference(psi::read_npy(path("twin") + "/surface_nm.npy"),
                           psi::read_npy(path("arv") + "/surface_nm.npy")),
            0.1);
  refused("--config '" + small_camera("Mono12") + "' --camera aravis:Fake_1 --out '" + path("m12") +
              "'",
          "Mono12");
}

// A camera that does not show the twin's scene (Aravis's fake, fed the twin here; a real one):
// the lock finds the pupil in its reference frames' fringe modulation, or takes --mask. On the
// twin's fringes the modulation finds the scene's own pupil, so the lock does as the twin
// camera's (measured: the same 6400 pixels and the same path error to the last digit).
TEST_F(MeasureCli, TheLockFindsThePupilOfACameraWithoutTheScenesInItsReferenceFrames) {
  const std::string cfg = write("drift16.toml",
                                "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                "pixel_format = \"Mono16\"\n[twin.cavity]\nin_fringes = true\n");
  const std::string common = "--config '" + cfg + "' --averages 10 --lock ";
  const Json twin = measure(common + "--out '" + path("twin") + "'");
  const Json arv = measure(common + "--camera aravis:Fake_1 --out '" + path("arv") + "'");
  const Json given = measure(common + "--camera aravis:Fake_1 --mask '" + path("twin") +
                             "/mask.png' --out '" + path("given") + "'");
  ASSERT_TRUE(twin.is_object() && arv.is_object() && given.is_object());
  EXPECT_EQ(twin["lock"]["pupil_source"], "given");
  EXPECT_EQ(arv["lock"]["pupil_source"], "modulation");
  EXPECT_EQ(given["lock"]["pupil_source"], "given");
  EXPECT_EQ(arv["lock"]["pupil_pixels"], twin["lock"]["pupil_pixels"]);
  EXPECT_EQ(arv["lock"]["locked_frames"], 45);
  EXPECT_NEAR(arv["path_error_rms_nm"].get<double>(), twin["path_error_rms_nm"].get<double>(),
              0.01);
  EXPECT_NEAR(given["path_error_rms_nm"].get<double>(), twin["path_error_rms_nm"].get<double>(),
              0.01);
  // Fringes too faint to find a pupil in: the lock cannot start, and says so (exit 4).
  const std::string flat = write("flat.toml",
                                 "[camera]\nwidth_px = 96\nheight_px = 96\n"
                                 "pixel_format = \"Mono16\"\nvisibility = 0.0001\n");
  const testing::CliResult r = run("measure --free-run --lock --camera aravis:Fake_1 --config '" +
                                   flat + "' --out '" + path("flat") + "'");
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_NE(r.err.find("the fringe lock found no pupil in its reference frames"), std::string::npos)
      << r.err;
  // A mask whose size is not the camera's: refused before anything runs.
  const std::string wide = write("wide.toml",
                                 "[camera]\nwidth_px = 128\nheight_px = 96\n"
                                 "pixel_format = \"Mono16\"\n");
  refused("--lock --camera aravis:Fake_1 --config '" + wide + "' --mask '" + path("twin") +
              "/mask.png' --out '" + path("m") + "'",
          "mask is 96 x 96 pixels, the camera's frames 128 x 96");
}

}  // namespace
}  // namespace piezoshift
