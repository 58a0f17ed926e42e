// `piezoshift run --daq comedi:` against the emulated NI PCI-6229 (emulation/comedi): the
// shipping program, unchanged, loads the emulation as libcomedi.so.0 through LD_LIBRARY_PATH.
// The board's facts are checked through libcomedi's API itself (dlopen), then the loop is closed
// on the twin behind it and compared with `--daq sim`, and device errors are injected.
#include <comedi_errno.h>
#include <comedilib.h>
#include <dlfcn.h>

#include <cerrno>
#include <cstdlib>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "http_client.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/io/csv_table.hpp"
#include "spawned_process.hpp"
#include "temp_dir_test.hpp"
#include "test_paths.hpp"

namespace {

using piezoshift::testing::slurp;
using piezoshift::testing::spawn;
using piezoshift::testing::Spawned;
using piezoshift::testing::wait_exit;

const std::string kEmulationDir = PIEZOSHIFT_COMEDI_EMULATION_DIR;

class ComediEmulation : public piezoshift::testing::TempDirTest {
 protected:
  // Starts `piezoshift args...` on the emulated board described by `toml`.
  Spawned spawn_emulated(const std::vector<std::string>& args, const std::string& toml) {
    const std::string settings = write("emulation.toml", toml);
    setenv("LD_LIBRARY_PATH", kEmulationDir.c_str(), 1);
    setenv("PIEZOSHIFT_COMEDI_EMULATION", settings.c_str(), 1);
    const Spawned s = spawn(args, path("out"), path("err"));
    unsetenv("LD_LIBRARY_PATH");
    unsetenv("PIEZOSHIFT_COMEDI_EMULATION");
    return s;
  }
  // The same, run to its end: its exit status.
  int run_emulated(const std::vector<std::string>& args, const std::string& toml) {
    return wait_exit(spawn_emulated(args, toml));
  }
  // `calibrate` on the twin (the emulation's default plant), written to `name`; its path.
  std::string twin_calibration(const std::string& name) {
    const std::string cal = path(name);
    EXPECT_EQ(wait_exit(spawn({"calibrate", "--out", cal}, path("out"), path("err"))), 0)
        << slurp(path("err"));
    return cal;
  }
  nlohmann::json record() { return nlohmann::json::parse(slurp(path("record.json"))); }
  std::string record_toml() { return "[record]\njson = \"" + path("record.json") + "\"\n"; }
};

// The API's functions, from the emulation loaded on its own.
struct Api {
  void* lib = nullptr;
  template <typename F>
  F get(const char* name) {
    return reinterpret_cast<F>(dlsym(lib, name));
  }
};

TEST_F(ComediEmulation, PresentsThePci6229AsNiPcimioDoes) {
  setenv("PIEZOSHIFT_COMEDI_EMULATION", write("e.toml", "").c_str(), 1);
  Api api{dlopen((kEmulationDir + "/libcomedi.so.0").c_str(), RTLD_NOW | RTLD_LOCAL)};
  ASSERT_NE(api.lib, nullptr) << dlerror();
  auto open = api.get<comedi_t* (*)(const char*)>("comedi_open");
  auto close = api.get<int (*)(comedi_t*)>("comedi_close");
  auto n_subdevices = api.get<int (*)(comedi_t*)>("comedi_get_n_subdevices");
  auto type = api.get<int (*)(comedi_t*, unsigned)>("comedi_get_subdevice_type");
  auto n_channels = api.get<int (*)(comedi_t*, unsigned)>("comedi_get_n_channels");
  auto maxdata = api.get<lsampl_t (*)(comedi_t*, unsigned, unsigned)>("comedi_get_maxdata");
  auto find_range = api.get<int (*)(comedi_t*, unsigned, unsigned, unsigned, double, double)>(
      "comedi_find_range");
  auto get_range =
      api.get<comedi_range* (*)(comedi_t*, unsigned, unsigned, unsigned)>("comedi_get_range");
  auto data_write = api.get<int (*)(comedi_t*, unsigned, unsigned, unsigned, unsigned, lsampl_t)>(
      "comedi_data_write");
  auto error = api.get<int (*)()>("comedi_errno");

  EXPECT_EQ(open("/dev/comedi7"), nullptr) << "only the configured device exists";
  EXPECT_EQ(error(), ENOENT);
  comedi_t* dev = open("/dev/comedi0");
  ASSERT_NE(dev, nullptr);
  EXPECT_EQ(n_subdevices(dev), 14);  // ni_mio_common's NI_NUM_SUBDEVICES
  EXPECT_EQ(type(dev, 0), COMEDI_SUBD_AI);
  EXPECT_EQ(type(dev, 1), COMEDI_SUBD_AO);
  EXPECT_EQ(type(dev, 2), COMEDI_SUBD_DIO);
  EXPECT_EQ(type(dev, 3), COMEDI_SUBD_UNUSED);
  EXPECT_EQ(n_channels(dev, 0), 32);
  EXPECT_EQ(n_channels(dev, 1), 4);
  EXPECT_EQ(n_channels(dev, 2), 32);
  EXPECT_EQ(maxdata(dev, 0, 0), 0xffffu);
  // The gauges' [-0.5, 10] V needs +-10 V (range 0); [0, 0.9] V fits +-1 V (range 2).
  EXPECT_EQ(find_range(dev, 0, 0, UNIT_volt, -0.5, 10.0), 0);
  EXPECT_EQ(find_range(dev, 0, 0, UNIT_volt, 0.0, 0.9), 2);
  EXPECT_EQ(find_range(dev, 1, 0, UNIT_volt, 0.0, 10.0), 0);
  EXPECT_EQ(find_range(dev, 1, 0, UNIT_volt, 0.0, 12.0), -1);
  EXPECT_DOUBLE_EQ(get_range(dev, 0, 0, 3)->max, 0.2);
  EXPECT_EQ(data_write(dev, 1, 0, 0, AREF_GROUND, 0x10000), -1) << "data above maxdata";
  EXPECT_EQ(error(), EINVAL);
  EXPECT_EQ(data_write(dev, 3, 0, 0, AREF_GROUND, 0), -1) << "an unused subdevice";
  EXPECT_EQ(error(), EINVAL_CHAN) << "libcomedi checks the channel first: it has none";
  EXPECT_EQ(data_write(dev, 1, 4, 0, AREF_GROUND, 0), -1) << "AO has channels 0..3";
  EXPECT_EQ(error(), EINVAL_CHAN) << "libcomedi's own check, before the kernel's";
  EXPECT_EQ(close(dev), 0);
  dlclose(api.lib);
  unsetenv("PIEZOSHIFT_COMEDI_EMULATION");
}

TEST_F(ComediEmulation, SoftCalibrationPolynomialsUndoTheRawConverters) {
  setenv("PIEZOSHIFT_COMEDI_EMULATION", write("e.toml", "").c_str(), 1);
  Api api{dlopen((kEmulationDir + "/libcomedi.so.0").c_str(), RTLD_NOW | RTLD_LOCAL)};
  ASSERT_NE(api.lib, nullptr) << dlerror();
  comedi_t* dev = api.get<comedi_t* (*)(const char*)>("comedi_open")("/dev/comedi0");
  ASSERT_NE(dev, nullptr);
  char* file = api.get<char* (*)(comedi_t*)>("comedi_get_default_calibration_path")(dev);
  EXPECT_STREQ(file, "/var/lib/comedi/calibrations/ni_pcimio_pci-6229_comedi0");
  comedi_calibration_t* cal =
      api.get<comedi_calibration_t* (*)(const char*)>("comedi_parse_calibration_file")(file);
  std::free(file);
  ASSERT_NE(cal, nullptr);
  auto softcal = api.get<int (*)(unsigned, unsigned, unsigned, comedi_conversion_direction,
                                 const comedi_calibration_t*, comedi_polynomial_t*)>(
      "comedi_get_softcal_converter");
  auto from_physical =
      api.get<lsampl_t (*)(double, const comedi_polynomial_t*)>("comedi_from_physical");
  auto to_physical =
      api.get<double (*)(lsampl_t, const comedi_polynomial_t*)>("comedi_to_physical");
  comedi_polynomial_t ao{}, ai{};
  ASSERT_EQ(softcal(1, 2, 0, COMEDI_FROM_PHYSICAL, cal, &ao), 0);
  ASSERT_EQ(softcal(0, 2, 0, COMEDI_TO_PHYSICAL, cal, &ai), 0);
  EXPECT_EQ(softcal(1, 2, 0, COMEDI_TO_PHYSICAL, cal, &ai), -1) << "an AO converts volts to codes";
  // AO channel 2's raw DAC: offset 0 codes, gain 1 - 4e-4 (board_model.cpp): 0 V is the mid code
  // 32768 and 5 V is 16384 codes above it, less the gain error.
  EXPECT_EQ(from_physical(0.0, &ao), 32768u);
  EXPECT_EQ(from_physical(5.0, &ao), 32768u + 16377u);  // 16384 * (1 - 4e-4) = 16377.4
  // AI channel 2: offset 1 code, gain 1 + 1.5e-4: the code 32769 reads 0 V.
  EXPECT_NEAR(to_physical(32769, &ai), 0.0, 1e-12);
  EXPECT_NEAR(to_physical(32769 + 16387, &ai), 5.0, 20.0 / 65536.0);  // 16384 * 1.00015 = 16386.5
  api.get<void (*)(comedi_calibration_t*)>("comedi_cleanup_calibration")(cal);
  api.get<int (*)(comedi_t*)>("comedi_close")(dev);
  dlclose(api.lib);
  unsetenv("PIEZOSHIFT_COMEDI_EMULATION");
}

// A staircase over the travel, as the paper's linearity protocol steps: the mean true position
// of each hold, from the emulation's series (comedi) or the run's log (sim).
const std::vector<double> kStairs_um = {2.0, 4.0, 6.0, 8.0, 10.0};
constexpr double kHold_s = 0.4;

std::string staircase_csv() {
  std::string csv = "t_s,zd_um\n0,0\n";
  double t = 0.0;
  for (const double z : kStairs_um) {
    csv += fmt::format("{},{}\n{},{}\n", t + 0.001, z, t + kHold_s, z);
    t += kHold_s;
  }
  return csv;
}

// Means of the three points' true displacement over the last half of each hold, from the
// columns t_s and <z>1_um, <z>2_um, <z>3_um of a CSV file.
std::vector<double> hold_means(const std::string& file, const std::string& z) {
  const piezoshift::io::CsvTable table = piezoshift::io::CsvTable::load(file);
  const std::vector<double> t = table.column("t_s");
  const std::vector<double> z1 = table.column(z + "1_um"), z2 = table.column(z + "2_um"),
                            z3 = table.column(z + "3_um");
  std::vector<double> sum(kStairs_um.size(), 0.0), n(kStairs_um.size(), 0.0);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const auto k = static_cast<std::size_t>(t[i] / kHold_s);
    if (k >= kStairs_um.size() || t[i] - kHold_s * static_cast<double>(k) < kHold_s / 2)
      continue;
    sum[k] += (z1[i] + z2[i] + z3[i]) / 3.0;
    n[k] += 1.0;
  }
  for (std::size_t k = 0; k < sum.size(); ++k)
    sum[k] = n[k] > 0 ? sum[k] / n[k] : NAN;
  return sum;
}

TEST_F(ComediEmulation, RunClosesTheLoopOnTheTwinAsTheSimBackendDoes) {
  const std::string cal = twin_calibration("cal.toml");
  ASSERT_FALSE(HasFailure());
  const std::string profile = write("stairs.csv", staircase_csv());
  const double duration_s = kHold_s * static_cast<double>(kStairs_um.size());
  const auto run_args = [&](const std::string& daq, int seed) {
    return std::vector<std::string>{"run",
                                    "--daq",
                                    daq,
                                    "--profile",
                                    profile,
                                    "--duration-s",
                                    fmt::format("{}", duration_s),
                                    "--calibration",
                                    cal,
                                    "--seed",
                                    std::to_string(seed),
                                    "--log",
                                    path("log.csv"),
                                    "--max-overruns",
                                    "1000000"};
  };
  // The twin through --daq sim at three seeds: the spread a seed makes.
  std::vector<std::vector<double>> sim;
  for (const int seed : {1, 2, 3}) {
    ASSERT_EQ(wait_exit(spawn(run_args("sim", seed), path("out"), path("err"))), 0)
        << slurp(path("err"));
    sim.push_back(hold_means(path("log.csv"), "truth"));
  }
  // The twin (seed 1) on the emulated board's wires, following the wall clock as a board's
  // plant does (in 0.1 ms steps where --daq sim takes the loop's 1 ms: another noise draw).
  const std::string toml = record_toml() + "csv = \"" + path("series.csv") +
                           "\"\ncsv_period_s = 0.001\n[twin]\nseed = 1\n";
  ASSERT_EQ(run_emulated(run_args("comedi:/dev/comedi0", 1), toml), 0) << slurp(path("err"));
  const std::vector<double> comedi = hold_means(path("series.csv"), "z");
  double spread_um = 0.0;  // the largest seed spread of any hold
  for (std::size_t k = 0; k < kStairs_um.size(); ++k) {
    const auto [lo, hi] = std::minmax({sim[0][k], sim[1][k], sim[2][k]});
    spread_um = std::max(spread_um, hi - lo);
  }
  // Measured: a spread of 4.3 nm, the emulated board within 1.5 nm of the seeds' mean. Swapped
  // channels or a wrong range would be off by micrometres. (The calibration polynomials, worth
  // about 1 nm here, are checked on their own above.)
  EXPECT_GT(spread_um, 0.0);
  for (std::size_t k = 0; k < kStairs_um.size(); ++k) {
    const double mean_um = (sim[0][k] + sim[1][k] + sim[2][k]) / 3.0;
    EXPECT_LT(std::fabs(comedi[k] - mean_um), 2.0 * spread_um)
        << "hold " << kStairs_um[k] << " um: comedi " << comedi[k] << ", sim seeds " << sim[0][k]
        << " " << sim[1][k] << " " << sim[2][k];
    EXPECT_NEAR(comedi[k], kStairs_um[k], 0.25) << "semi-closed loop on the calibrated twin";
  }
  const nlohmann::json rec = record();
  EXPECT_EQ(rec["failed_transactions"], 0);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_LT(std::fabs(rec["ao_V"][i].get<double>()), 1e-3) << "the ramp to 0 V at the end";
}

// `serve` on the emulated board: a GCS client's move reaches its target through the board.
TEST_F(ComediEmulation, ServeMovesTheStageThroughTheBoard) {
  const std::string cal = twin_calibration("cal.toml");
  ASSERT_FALSE(HasFailure());
  const Spawned s =
      spawn_emulated({"serve", "--daq", "comedi:/dev/comedi0", "--port", "0", "--calibration", cal,
                      "--duration-s", "3", "--max-overruns", "1000000"},
                     record_toml());
  const std::uint16_t port = piezoshift::testing::wait_for_gcs_port(path("out"), path("err"));
  ASSERT_NE(port, 0);
  piezoshift::testing::HttpConnection gcs(port);
  const auto ask = [&](const std::string& line) {
    gcs.send(line + "\n");
    std::string answer;
    for (int i = 0; i < 100 && answer.find('\n') == std::string::npos; ++i)
      gcs.read_some(answer, 0.05);
    return answer;
  };
  gcs.send("SVO Z 1\n");
  gcs.send("MOV Z 4\n");
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  const std::string pos = ask("POS? Z");
  ASSERT_EQ(pos.rfind("Z=", 0), 0u) << pos;
  EXPECT_NEAR(std::stod(pos.substr(2)), 4.0, 0.01) << "the gauges' position, on target";
  EXPECT_EQ(ask("ERR?"), "0\n");
  EXPECT_EQ(wait_exit(s), 0) << slurp(path("err"));
  const nlohmann::json rec = record();
  EXPECT_GT(rec["transactions"].get<int>(), 2000) << "the loop ran on the board";
  EXPECT_EQ(rec["failed_transactions"], 0);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_LT(std::fabs(rec["ao_V"][i].get<double>()), 2e-4) << "AO " << i << " at 0 V";
}

// The guided calibration on the emulated board, its interferometer readings from the
// emulation's live XL-80-like logs; the operator moving the optics is the test re-pointing a
// link when the program says where they go. Acceptance tier: it runs in real time (~150 s).
TEST_F(ComediEmulation, GuidedCalibrationOnTheBoardAgreesWithTheTwinCalibration) {
  const std::string twin_cal = twin_calibration("twin_cal.toml");
  ASSERT_FALSE(HasFailure());
  const std::filesystem::path logs = path("ifm");
  std::filesystem::create_directory(logs);
  const std::filesystem::path optics = logs / "optics.csv";
  const auto point_at = [&](const std::string& name) {  // atomic: the reader never sees none
    const std::filesystem::path next = logs / "optics.next";
    std::filesystem::remove(next);
    std::filesystem::create_symlink(logs / (name + ".csv"), next);
    std::filesystem::rename(next, optics);
  };
  point_at("P1");
  // The overrun rule off: a calibration of minutes on a shared test machine would otherwise end
  // on one late burst; the test is about the board and the procedure, not the host.
  const std::string config = write("safety.toml", "[safety]\ntrip_on_overruns = 0\n");
  const std::string guided_cal = path("guided_cal.toml");
  const Spawned s =
      spawn_emulated({"calibrate", "--daq", "comedi:/dev/comedi0", "--interferometer",
                      "file:" + optics.string(), "--config", config, "--out", guided_cal},
                     record_toml() + "[interferometer]\nlog_folder = \"" + logs.string() + "\"\n");
  // Follow the instructions as they appear on stderr, as the operator would.
  std::size_t seen = 0;
  int status = -1;
  for (;;) {
    const std::string out = slurp(path("err"));
    for (std::size_t at; (at = out.find("put the", seen)) != std::string::npos;) {
      const std::size_t end = out.find('\n', at);
      if (end == std::string::npos)
        break;
      const std::string line = out.substr(at, end - at);
      for (const char* p : {"P1", "P2", "P3"})
        if (line.find(std::string("measurement point ") + p) != std::string::npos)
          point_at(p);
      if (line.find("at the centre") != std::string::npos)
        point_at("centre");
      seen = end;
    }
    int wstatus = 0;
    if (waitpid(s.pid, &wstatus, WNOHANG) == s.pid) {
      status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(status, 0) << slurp(path("err")) << slurp(path("out"));
  const auto guided = piezoshift::calibration::load_calibration_file(guided_cal);
  const auto twin = piezoshift::calibration::load_calibration_file(twin_cal);
  // Measured: A within 0.00026 of the twin calibration's, p within 5 nm over the travel. The
  // bounds are about twice and four times that, room for another noise draw of the readings;
  // a fault of the board's path (a channel, a range, a polynomial) moves them by far more.
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(guided.matrix.a[r][c], twin.matrix.a[r][c], 6e-4) << r << "," << c;
  for (const double z_um : {0.0, 2.0, 5.5, 8.0, 11.0})
    EXPECT_NEAR(guided.polynomial(z_um), twin.polynomial(z_um), 0.02) << z_um << " um";
  EXPECT_EQ(record()["failed_transactions"], 0);
}

struct DeviceError {
  std::string fault_toml;
  std::string fault_reason;
  std::string device_error;  // the run's "device error" line, empty: none
};

TEST_F(ComediEmulation, InjectedDeviceErrorsEndInNamedFaultsWithOutputsAt0V) {
  const std::vector<DeviceError> cases = {
      {"ai_timeout_at_s = 0.3", "daq-read", "Timer expired"},
      {"io_error_at_s = 0.3", "daq-read", "Input/output error"},
      {"ai_open_at_s = 0.3\nai_open_channel = 1", "sgs-rail", ""},
  };
  for (const DeviceError& c : cases) {
    SCOPED_TRACE(c.fault_toml);
    const int status = run_emulated({"run", "--daq", "comedi:/dev/comedi0", "--step-um", "5",
                                     "--duration-s", "1", "--json", "--max-overruns", "1000000"},
                                    record_toml() + "[faults]\n" + c.fault_toml + "\n");
    EXPECT_EQ(status, 3) << slurp(path("err"));
    const nlohmann::json j = nlohmann::json::parse(slurp(path("out")));
    ASSERT_FALSE(j["faults_latched"].empty());
    EXPECT_EQ(j["faults_latched"][0]["reason"], c.fault_reason);
    EXPECT_NEAR(j["faults_latched"][0]["time_s"].get<double>(), 0.3, 0.02);
    if (c.fault_reason == "sgs-rail") {
      EXPECT_EQ(j["faults_latched"][0]["channel"], 2);
    }
    EXPECT_EQ(j["device_error"],
              c.device_error.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.device_error));
    EXPECT_TRUE(j["outputs_at_0_V"].get<bool>());
    const nlohmann::json rec = record();
    for (std::size_t i = 0; i < 3; ++i)  // 0 V within the DAC's half code, 0.15 mV
      EXPECT_LT(std::fabs(rec["ao_V"][i].get<double>()), 2e-4) << "AO " << i;
  }
}

TEST_F(ComediEmulation, OutputsTheDeviceWillNotZeroAreReportedNotHidden) {
  const int status = run_emulated({"run", "--daq", "comedi:/dev/comedi0", "--step-um", "5",
                                   "--duration-s", "1", "--json", "--max-overruns", "1000000"},
                                  record_toml() + "[faults]\nao_busy_at_s = 0.3\n");
  EXPECT_EQ(status, 3);
  const nlohmann::json j = nlohmann::json::parse(slurp(path("out")));
  EXPECT_FALSE(j["outputs_at_0_V"].get<bool>());
  EXPECT_EQ(j["device_error"], "Device or resource busy");
  const std::string err = slurp(path("err"));
  EXPECT_NE(err.find("switch the amplifier off"), std::string::npos) << err;
  EXPECT_GT(record()["ao_V"][0].get<double>(), 1.0) << "the emulated outputs did hold";
}

// A missing subdevice, a missing calibration, a wrong device and a range that cannot hold the
// amplifiers' 0..10 V: each found before anything is written to the outputs.
TEST_F(ComediEmulation, BoardsItCannotUseExit2NamingWhy) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"[board]\nmodel = \"pci-6220\"\n", "no analog output subdevice"},
      {"[board]\ncalibrated = false\n", "comedi_soft_calibrate"},
      {"[board]\ndevice = \"/dev/comedi1\"\n", "cannot open the DAQ device"},
      {"[board]\nao_reference_V = 5\n", "subdevice 1 channel 0 has no range holding [0, 10] V"},
  };
  for (const auto& [toml, message] : cases) {
    SCOPED_TRACE(toml);
    EXPECT_EQ(run_emulated({"run", "--daq", "comedi:/dev/comedi0", "--duration-s", "1"}, toml), 2);
    const std::string err = slurp(path("err"));
    EXPECT_NE(err.find(message), std::string::npos) << err;
    EXPECT_NE(err.find("/dev/comedi0"), std::string::npos) << err;
  }
}

}  // namespace
