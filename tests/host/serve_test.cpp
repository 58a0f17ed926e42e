// `piezoshift serve` end to end: the program is spawned as an operator would start it, and the
// in-project GCS client drives it over loopback. The loop runs on the real clock; the overrun rule
// is lifted (--max-overruns) so that a loaded test machine cannot turn a test into a fault run:
// timing is not what these tests check. No wall-clock asserts: waits are generous upper bounds.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/spawned_process.hpp"
#include "piezoshift/host/gcs_client.hpp"

namespace {

namespace fs = std::filesystem;
using piezoshift::host::GcsClient;
using piezoshift::testing::slurp;
using piezoshift::testing::spawn;
using piezoshift::testing::Spawned;
using piezoshift::testing::wait_exit;

// "Z=5.000000" -> 5.0 for the named axis; NaN when absent.
double value_of(const std::vector<std::string>& lines, const std::string& key) {
  for (const std::string& l : lines)
    if (l.rfind(key + "=", 0) == 0)
      return std::stod(l.substr(key.size() + 1));
  return std::nan("");
}

class Serve : public piezoshift::testing::TempDirTest {
 protected:
  // One twin calibration for the suite (`calibrate --pid paper`, under a second): POS? is
  // compared with the interferometer, which only a calibration of this twin makes agree.
  static void SetUpTestSuite() {
    suite_dir_ = fs::temp_directory_path() / ("piezoshift_serve_" + std::to_string(getpid()));
    fs::create_directories(suite_dir_);
    calibration_ = (suite_dir_ / "twin.toml").string();
    const std::string cmd = "'" + piezoshift::testing::cli_path() +
                            "' calibrate --pid paper --out '" + calibration_ + "' >/dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  }
  static void TearDownTestSuite() { fs::remove_all(suite_dir_); }

  void TearDown() override {
    if (server_.pid > 0) {  // a failed test: do not leave the server running
      kill(server_.pid, SIGKILL);
      wait_exit(server_);
    }
    TempDirTest::TearDown();
  }

  // Starts the server on a free port; returns the port (0 when it did not come up).
  std::uint16_t start(std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"serve",          "--port",    "0",
                                  "--max-overruns", "1000000",   "--json",
                                  "--calibration",  calibration_};
    args.insert(args.end(), extra.begin(), extra.end());
    server_ = spawn(args, path("out.txt"), path("err.txt"));
    return piezoshift::testing::wait_for_gcs_port(path("out.txt"), path("err.txt"));
  }

  // SIGTERM, exit status 0, and the JSON summary.
  nlohmann::json stop() {
    kill(server_.pid, SIGTERM);
    const int status = wait_exit(server_);
    server_.pid = -1;
    EXPECT_EQ(status, 0) << slurp(path("err.txt"));
    const std::string out = slurp(path("out.txt"));
    const std::size_t brace = out.find('{');
    if (brace == std::string::npos) {
      ADD_FAILURE() << "no summary: " << out;
      return {};
    }
    return nlohmann::json::parse(out.substr(brace));
  }

  // Polls ONT? until every axis is on target; false after 10 s.
  static bool wait_on_target(GcsClient& c) {
    for (int i = 0; i < 2000; ++i) {
      const auto a = c.query_lines("ONT?");
      if (a == std::vector<std::string>{"Z=1", "U=1", "V=1"})
        return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return false;
  }

  // Polls DRL? until table 1 holds n points (the assertions on the data follow); at most 10 s.
  static void wait_recorded(GcsClient& c, int n) {
    for (int i = 0; i < 2000 && std::stoi(c.query_lines("DRL? 1")[0].substr(2)) < n; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }

  static int error(GcsClient& c) { return std::stoi(c.query("ERR?")); }

  static fs::path suite_dir_;
  static std::string calibration_;
  Spawned server_;
};

fs::path Serve::suite_dir_;
std::string Serve::calibration_;

// What TMN? and TMX? advertise is reachable by one move, from rest and from mid-travel, without
// a fault; one step beyond is refused up front (error 7), never a fault halfway.
TEST_F(Serve, EveryZUpToTheAdvertisedTravelIsReachedByOneMove) {
  const std::uint16_t port = start();
  ASSERT_NE(port, 0);
  GcsClient c("127.0.0.1", port);
  const double z_max = value_of(c.query_lines("TMX?"), "Z");
  const double z_min = value_of(c.query_lines("TMN?"), "Z");
  c.send("SVO Z 1 U 1 V 1");
  for (const double z : {z_max, 5.0, z_max, z_min, z_max}) {
    c.send(fmt::format("MOV Z {} U 0 V 0", z));
    EXPECT_EQ(error(c), 0) << z;
    ASSERT_TRUE(wait_on_target(c)) << "MOV Z " << z;
    EXPECT_NEAR(value_of(c.query_lines("POS?"), "Z"), z, 0.01);
  }
  // MOV Z alone, each time after a servo-on that takes the gauges' pose, their tilt noise too, as
  // the target (it was once refused with 7 at the ends)
  for (const double z : {z_max, z_min, 5.0, z_max}) {
    c.send("SVO Z 0 U 0 V 0");
    c.send("SVO Z 1 U 1 V 1");
    c.send(fmt::format("MOV Z {}", z));
    EXPECT_EQ(error(c), 0) << z;
    ASSERT_TRUE(wait_on_target(c)) << "MOV Z " << z << " alone";
    EXPECT_NEAR(value_of(c.query_lines("POS?"), "Z"), z, 0.01);
  }
  c.send(fmt::format("MOV Z {}", z_max + 0.1));
  EXPECT_EQ(error(c), 7);
  c.send(fmt::format("MOV Z {}", z_min - 0.1));
  EXPECT_EQ(error(c), 7);
  EXPECT_EQ(c.query_lines("SVO?"), (std::vector<std::string>{"Z=1", "U=1", "V=1"}));
}

TEST_F(Serve, IdentifiesListsAxesMovesOnTargetAndAgreesWithTheInterferometer) {
  const std::uint16_t port = start();
  ASSERT_NE(port, 0);
  GcsClient c("127.0.0.1", port);
  EXPECT_NE(c.query("*IDN?").find("piezoshift"), std::string::npos);
  EXPECT_EQ(c.query("CSV?"), "2.0\n");
  EXPECT_EQ(c.query("SAI? ALL"), "Z \nU \nV\n");
  EXPECT_EQ(c.query_lines("PUN?"), (std::vector<std::string>{"Z=um", "U=urad", "V=urad"}));
  EXPECT_EQ(c.query_lines("SVO?"), (std::vector<std::string>{"Z=0", "U=0", "V=0"}));
  // The calibration file's [travel] bounds Z: the travel one move from rest reaches (11.1 um on
  // this twin; Section 4.1's creeping search reaches 11.5), and the lowest Z one move down from
  // there reaches (0.05 um: the stacks' hysteresis at 0 V).
  EXPECT_NEAR(value_of(c.query_lines("TMX?"), "Z"), 11.1, 0.3);
  EXPECT_NEAR(value_of(c.query_lines("TMN?"), "Z"), 0.05, 0.05);

  c.send("SVO Z 1 U 1 V 1");
  EXPECT_EQ(error(c), 0);
  c.send("MOV Z 5 U 20 V -15");
  EXPECT_EQ(error(c), 0);
  ASSERT_TRUE(wait_on_target(c));
  const auto pos = c.query_lines("POS?");
  EXPECT_NEAR(value_of(pos, "Z"), 5.0, 0.01);  // the --on-target-um default
  EXPECT_NEAR(value_of(pos, "U"), 20.0, 0.5);
  EXPECT_NEAR(value_of(pos, "V"), -15.0, 0.5);

  // Position and interferometer side by side in the recorder, 200 points at rest.
  const char* axes[] = {"Z", "U", "V"};
  for (int i = 0; i < 3; ++i) {
    c.send("DRC " + std::to_string(2 * i + 1) + " " + axes[i] + " 2");
    c.send("DRC " + std::to_string(2 * i + 2) + " " + axes[i] + " 90");
  }
  EXPECT_EQ(error(c), 0);
  wait_recorded(c, 200);
  const auto data = c.query_lines("DRR? 1 200");
  std::vector<std::vector<double>> rows;
  for (const std::string& l : data) {
    if (l.rfind('#', 0) == 0)
      continue;
    std::istringstream in(l);
    std::vector<double> row;
    for (double v; in >> v;)
      row.push_back(v);
    rows.push_back(row);
  }
  ASSERT_EQ(rows.size(), 200u);
  double mean_diff[3] = {0, 0, 0};
  for (const auto& r : rows) {
    ASSERT_EQ(r.size(), 6u);
    for (int i = 0; i < 3; ++i)
      mean_diff[i] += (r[2 * i] - r[2 * i + 1]) / 200.0;
  }
  // The twin-calibrated feedforward, inverted, agrees with the interferometer to its linearity:
  // measured 0.2 nm and < 0.04 urad; allowed 10 nm and 0.3 urad.
  EXPECT_LT(std::fabs(mean_diff[0]), 0.01);
  EXPECT_LT(std::fabs(mean_diff[1]), 0.3);
  EXPECT_LT(std::fabs(mean_diff[2]), 0.3);

  c.send("MVR Z 1");
  EXPECT_EQ(value_of(c.query_lines("MOV? Z"), "Z"), 6.0);
  ASSERT_TRUE(wait_on_target(c));
  EXPECT_NEAR(value_of(c.query_lines("POS? Z"), "Z"), 6.0, 0.01);

  const nlohmann::json summary = stop();
  EXPECT_EQ(summary.at("stop_reason"), "SIGTERM");
  EXPECT_EQ(summary.at("faults"), 0);
  EXPECT_EQ(summary.at("gcs_errors"), 0);
  EXPECT_EQ(summary.at("clients_accepted"), 1);
}

// Polls a single-character query (#5, #9) until it answers `want`; false after 10 s.
bool wait_mask(GcsClient& c, char byte, const std::string& want) {
  for (int i = 0; i < 2000; ++i) {
    c.send_raw(std::string(1, byte));
    if (c.read_answer() == want)
      return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

// The data rows of a DRR? answer (the lines after "# END_HEADER").
std::vector<std::vector<double>> data_rows(const std::vector<std::string>& lines) {
  std::vector<std::vector<double>> rows;
  bool data = false;
  for (const std::string& l : lines) {
    if (data) {
      std::istringstream in(l);
      std::vector<double> row;
      for (double v; in >> v;)
        row.push_back(v);
      rows.push_back(row);
    }
    data = data || l == "# END_HEADER";
  }
  return rows;
}

// What a lab script does through PI's Python library (PIPython: pitools.startup, waitontarget,
// the data recorder helper, a wave generator sample), spoken here on the wire: every command
// followed by ERR? as PIPython's default error check does, single-character commands as the
// byte alone.
TEST_F(Serve, ALabScriptStartsUpMovesRecordsAndPlaysAWaveTable) {
  const std::uint16_t port = start();
  ASSERT_NE(port, 0);
  GcsClient c("127.0.0.1", port, 2.0);  // a short timeout: no answer may go missing
  const auto ok = [&](const std::string& command) {
    c.send(command);
    EXPECT_EQ(error(c), 0) << command;
  };

  // Start-up: the axes and their stages, stop all (#24: error 10, as PI), ready, servo on.
  EXPECT_EQ(c.query_lines("SAI? ALL"), (std::vector<std::string>{"Z", "U", "V"}));
  EXPECT_EQ(c.query_lines("CST?"),
            (std::vector<std::string>{"Z=PIEZOSHIFT_TRIPOD", "U=PIEZOSHIFT_TRIPOD",
                                      "V=PIEZOSHIFT_TRIPOD"}));
  c.send_raw("\x18");
  EXPECT_EQ(error(c), 10);
  c.send_raw("\x07");
  EXPECT_EQ(c.read_answer(), "\xB1\n");
  ok("SVO Z 1 U 1 V 1");
  EXPECT_EQ(c.query("SPA? 1 0x0E000200"), "1 0x0E000200=0.001\n");  // servo cycle, s
  EXPECT_EQ(c.query("SPA? 1 0x16000200"), "1 0x16000200=65536\n");  // 8 tables x 8192

  // A move, waited for through #5 (the moving mask) ...
  ok("MOV Z 5");
  ASSERT_TRUE(wait_mask(c, '\x05', "0\n"));
  EXPECT_NEAR(value_of(c.query_lines("POS? Z"), "Z"), 5.0, 0.01);
  // ... and one through ONT?, recorded as a step: target and position, every servo cycle.
  ok("DRC 1 Z 1");
  ok("DRC 2 Z 2");
  ok("RTR 1");
  ok("DRT 0 1");  // record from the next command that changes the position
  ok("MOV Z 6");
  ASSERT_TRUE(wait_on_target(c));
  wait_recorded(c, 100);
  const std::string answer = c.query("DRR? 1 100 1 2");
  for (const char* header :
       {"# TYPE = 1 \n", "# SEPARATOR = 32 \n", "# DIM = 2 \n", "# SAMPLE_TIME = 0.001 \n",
        "# NDATA = 100 \n", "# NAME0 = Target position of axis Z (um) \n",
        "# NAME1 = Current position of axis Z (um) \n", "# END_HEADER \n"})
    EXPECT_NE(answer.find(header), std::string::npos) << header << answer;
  const auto step = data_rows(GcsClient::split_answer(answer));
  ASSERT_EQ(step.size(), 100u);
  // The first point is the tick that applied the move: target 6, the stage still at 5.
  EXPECT_EQ(step[0][0], 6.0);
  EXPECT_NEAR(step[0][1], 5.0, 0.01);
  EXPECT_NEAR(step[99][1], 6.0, 0.02);  // settled within 100 ms (the paper: < 0.3 s)

  // A wave table of 100 points (a raised cosine, 5 -> 6 -> 5 um), written in bunches of 10 as
  // PIPython's writewavepoints does, played twice at one point per servo cycle and recorded.
  std::vector<double> table(100);
  for (std::size_t i = 0; i < table.size(); ++i)
    table[i] = 5.5 - 0.5 * std::cos(2.0 * M_PI * static_cast<double>(i) / 100.0);
  for (std::size_t b = 0; b < 10; ++b) {
    std::string line = std::string("WAV 1 ") + (b == 0 ? "X" : "&") + " PNT 1 10";
    for (std::size_t i = 0; i < 10; ++i)
      line += fmt::format(" {:.17g}", table[10 * b + i]);
    ok(line);
  }
  EXPECT_EQ(c.query("WAV? 1 1"), "1 1=100\n");
  ok("WSL 1 1");
  ok("WGC 1 2");
  ok("WTR 1 1 0");
  ok("MOV Z 5");
  ASSERT_TRUE(wait_on_target(c));
  ok("WGO 1 1");
  c.send_raw("\x09");
  EXPECT_EQ(c.read_answer(), "1\n");  // generator 1 runs
  EXPECT_EQ(c.query("WGO? 1"), "1=1\n");
  ASSERT_TRUE(wait_mask(c, '\x09', "0\n"));
  wait_recorded(c, 300);
  const auto wave = data_rows(c.query_lines("DRR? 1 300 1 2"));
  ASSERT_EQ(wave.size(), 300u);
  // Sample-exact: recorded point k is table point k mod 100, from the tick that started it; after
  // the two cycles the target holds the last point.
  for (std::size_t k = 0; k < 300; ++k)
    EXPECT_NEAR(wave[k][0], table[k < 200 ? k % 100 : 99], 1e-8) << k;
  double worst_um = 0.0;
  for (const auto& row : wave)
    worst_um = std::max(worst_um, std::fabs(row[1] - row[0]));
  EXPECT_LT(worst_um, 0.3);  // the loop's lag on a 1 um, 100 ms cosine
  EXPECT_NEAR(value_of(c.query_lines("MOV? Z"), "Z"), table[99], 1e-6);

  // What the server does not implement is refused at once, never left unanswered.
  for (const char* query : {"FRF?", "SPA? 1 0x7000000", "WAV? 9 1"}) {
    EXPECT_EQ(c.query(query), "\n") << query;
    EXPECT_NE(error(c), 0) << query;
  }
  c.send("FRF Z");
  EXPECT_EQ(error(c), 2);

  const nlohmann::json summary = stop();
  EXPECT_EQ(summary.at("faults"), 0);
  EXPECT_EQ(summary.at("samples_dropped"), 0);
}

TEST_F(Serve, RecordsAtTheRateAskedAndAnswersInGcsDataForm) {
  const std::uint16_t port = start();
  ASSERT_NE(port, 0);
  GcsClient c("127.0.0.1", port);
  c.send("RTR 2");
  EXPECT_EQ(c.query("RTR?"), "2\n");
  c.send("DRC 1 1 7");  // amplifier voltage of channel 1
  EXPECT_EQ(c.query_lines("DRC? 1"), (std::vector<std::string>{"1=1 7"}));
  c.send("SVA Z 30");  // open loop: 30 V on every channel, the recording starts again
  EXPECT_EQ(error(c), 0);
  wait_recorded(c, 100);
  const std::string answer = c.query("DRR? 1 100 1 2");
  const auto lines = GcsClient::split_answer(answer);
  ASSERT_GT(lines.size(), 100u);
  EXPECT_NE(answer.find("# SAMPLE_TIME = 0.002 \n"), std::string::npos);  // 2 cycles of 1 ms
  EXPECT_NE(answer.find("# NDATA = 100 \n"), std::string::npos);
  EXPECT_NE(answer.find("# DIM = 2 \n"), std::string::npos);
  EXPECT_NE(answer.find("# NAME0 = Voltage of output channel 1 (V) \n"), std::string::npos);
  EXPECT_EQ(lines[lines.size() - 101], "# END_HEADER");
  // The slew-limited ramp to 30 V (1.5 V/ms at the DAQ, 22.5 V/ms at the stack) then 30 V.
  std::istringstream last(lines.back());
  double volts = 0.0;
  last >> volts;
  EXPECT_NEAR(volts, 30.0, 1e-3);
  EXPECT_EQ(value_of(c.query_lines("VOL? 2"), "2"), 30.0);
  stop();
}

TEST_F(Serve, EveryErrorPathQueuesItsGcsNumberAndNoQueryLeavesTheClientWaiting) {
  const std::uint16_t port = start();
  ASSERT_NE(port, 0);
  GcsClient c("127.0.0.1", port);
  const std::vector<std::pair<std::string, int>> cases{
      {"FOO?", 2},         {"MOV Z 5", 5},        {"POS? Q", 15},    {"MOV Z", 24},
      {"SVO Z 1 U 0", 17}, {"SVA Z 151", 66},     {"SVA Z abc", 25}, {"DRC 9 Z 2", 57},
      {"DRC 1 Z 4", 58},   {"DRR? 1 100000", 77}, {"DRC 2 Z 0", 0},  {"DRR? 1 1 2", 78},
      {"RTR 0", 17},       {"SVO Z 1", 0},        {"SVA Z 10", 79},  {"MOV Z 11.6", 7},
      {"MOV U 100000", 7}, {"MOV Z 1 Z 2", 22},   {"STP", 10}};
  for (const auto& [command, code] : cases) {
    // A failed query answers one empty line at once (the client's timeout is 5 s; a lost answer
    // would throw), a failed set command nothing.
    if (command.substr(0, command.find(' ')).back() == '?')
      EXPECT_EQ(c.query(command), "\n") << command;
    else
      c.send(command);
    EXPECT_EQ(error(c), code) << command;
  }
  EXPECT_EQ(error(c), 0);  // the queue is empty again
  const nlohmann::json summary = stop();
  EXPECT_EQ(summary.at("gcs_errors"), 17);
}

TEST_F(Serve, SeveralClientsAtOnceEachWithItsOwnErrorQueue) {
  const std::uint16_t port = start({"--max-clients", "3"});
  ASSERT_NE(port, 0);
  std::vector<std::unique_ptr<GcsClient>> clients;
  for (int i = 0; i < 3; ++i)
    clients.push_back(std::make_unique<GcsClient>("127.0.0.1", port));
  clients[0]->send("NOPE");
  clients[1]->send("SVO Z 1");
  EXPECT_EQ(error(*clients[1]), 0);
  EXPECT_EQ(clients[2]->query_lines("SVO? Z"), (std::vector<std::string>{"Z=1"}));
  clients[2]->send("MOV Z 3");
  EXPECT_TRUE(wait_on_target(*clients[0]));  // all see one stage
  EXPECT_EQ(error(*clients[2]), 0);
  EXPECT_EQ(error(*clients[0]), 2);
  // A fourth is one too many: accepted and closed at once; the three go on.
  GcsClient extra("127.0.0.1", port);
  EXPECT_TRUE(extra.wait_closed(10.0));
  EXPECT_NEAR(value_of(clients[1]->query_lines("POS? Z"), "Z"), 3.0, 0.01);
  const nlohmann::json summary = stop();
  EXPECT_EQ(summary.at("clients_accepted"), 3);
  EXPECT_EQ(summary.at("clients_refused"), 1);
}

// A client that connects after a fault latched learns it as from a PI controller: its
// first ERR? is -1024 (then 0), and SVO? answers 0.
TEST_F(Serve, AClientConnectingAfterAFaultReadsItFromErr) {
  const std::uint16_t port = start({"--fault", "sgs-open@0.3:1"});
  ASSERT_NE(port, 0);
  {
    GcsClient first("127.0.0.1", port);
    first.send("SVO Z 1");
    EXPECT_EQ(error(first), 0);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the fault latches at 0.3 s
  GcsClient late("127.0.0.1", port);
  EXPECT_EQ(late.query_lines("SVO? Z"), std::vector<std::string>{"Z=0"});
  EXPECT_EQ(error(late), -1024);
  EXPECT_EQ(error(late), 0);
  const nlohmann::json summary = stop();
  EXPECT_GE(summary.at("faults"), 1);
}

TEST_F(Serve, GarbageOversizedLinesAndDisconnectsMidAnswerLeaveTheLoopRunning) {
  const std::uint16_t port = start({"--max-line-bytes", "256"});
  ASSERT_NE(port, 0);
  {
    GcsClient rude("127.0.0.1", port);
    rude.send_raw(std::string("\x00\xff\x01 MOV\r\n", 9));
    EXPECT_EQ(error(rude), 2);
    rude.send_raw(std::string(10000, 'A') + "\n");
    EXPECT_EQ(error(rude), 3);
    EXPECT_EQ(error(rude), 0);
    // Ask for a long answer many times and hang up without reading it.
    for (int i = 0; i < 200; ++i)
      rude.send("HLP?");
    rude.close();
  }
  GcsClient c("127.0.0.1", port);
  c.send("SVO Z 1");
  c.send("MOV Z 2");
  EXPECT_TRUE(wait_on_target(c));
  EXPECT_NEAR(value_of(c.query_lines("POS? Z"), "Z"), 2.0, 0.01);
  const nlohmann::json summary = stop();
  EXPECT_EQ(summary.at("faults"), 0);
  EXPECT_EQ(summary.at("samples_dropped"), 0);
  EXPECT_EQ(summary.at("clients_accepted"), 2);
}

TEST_F(Serve, TheGcsCommandSendsCommandsAndPrintsTheAnswersOfQueries) {
  const std::uint16_t port = start();
  ASSERT_NE(port, 0);
  const std::vector<std::string> args{
      "gcs", "--port", std::to_string(port), "--transcript", "SVO Z 1", "SVO? Z", "#7", "#5"};
  const Spawned client = spawn(args, path("gcs.txt"), path("gcs_err.txt"));
  EXPECT_EQ(wait_exit(client), 0) << slurp(path("gcs_err.txt"));
  const std::string out = slurp(path("gcs.txt"));
  EXPECT_EQ(out.rfind("> SVO Z 1\n> SVO? Z\nZ=1\n> #7\n0xB1\n> #5\n", 0), 0u) << out;
  // A command without an answer says on stderr that it was done; stdout keeps the answers only.
  EXPECT_EQ(slurp(path("gcs_err.txt")), "piezoshift gcs: SVO Z 1: done (ERR? 0)\n");
  // A command that fails: the ERR? after it gives the number and PI's text, exit status 3, and
  // the commands after it are not sent.
  const Spawned bad = spawn({"gcs", "--port", std::to_string(port), "MOV Z 20", "MOV Z 1"},
                            path("gcs3.txt"), path("gcs3_err.txt"));
  EXPECT_EQ(wait_exit(bad), 3);
  EXPECT_EQ(slurp(path("gcs3_err.txt")),
            "piezoshift gcs: MOV Z 20: GCS error 7: Position out of limits\n");
  const Spawned unknown = spawn({"gcs", "--port", std::to_string(port), "FOO?"}, path("gcs4.txt"),
                                path("gcs4_err.txt"));
  EXPECT_EQ(wait_exit(unknown), 3);
  EXPECT_EQ(slurp(path("gcs4_err.txt")), "piezoshift gcs: FOO?: GCS error 2: Unknown command\n");
  stop();
  // Nobody listening any more: exit 2 naming the address.
  const Spawned refused = spawn({"gcs", "--port", std::to_string(port), "*IDN?"}, path("gcs2.txt"),
                                path("gcs2_err.txt"));
  EXPECT_EQ(wait_exit(refused), 2);
  EXPECT_NE(slurp(path("gcs2_err.txt")).find("127.0.0.1:" + std::to_string(port)),
            std::string::npos)
      << slurp(path("gcs2_err.txt"));
}

// `curl -X POST --data-binary $'SVO Z 1 U 1 V 1\nMOV Z 10\n' http://127.0.0.1:PORT/`
// at the GCS port switched the servo on and moved the stage. Its first line is HTTP's: the
// connection is closed before anything of it runs.
TEST_F(Serve, AnHttpRequestToTheGcsPortRunsNothing) {
  const std::uint16_t port = start();
  ASSERT_NE(port, 0);
  const std::string body = "SVO Z 1 U 1 V 1\nMOV Z 10\n";
  GcsClient c("127.0.0.1", port);
  const double target_before = value_of(c.query_lines("MOV? Z"), "Z");
  {
    GcsClient curl("127.0.0.1", port);
    curl.send_raw(fmt::format(
        "POST / HTTP/1.1\r\nHost: 127.0.0.1:{}\r\nUser-Agent: curl/7.88.1\r\nAccept: */*\r\n"
        "Content-Length: {}\r\nContent-Type: application/x-www-form-urlencoded\r\n\r\n{}",
        port, body.size(), body));
    EXPECT_TRUE(curl.wait_closed(10.0));
  }
  EXPECT_EQ(c.query("SVO? Z"), "Z=0\n");
  EXPECT_EQ(value_of(c.query_lines("MOV? Z"), "Z"), target_before);
  EXPECT_EQ(error(c), 0);
  stop();
}

// `piezoshift gcs` against a server that never ends its answer buffered 8.6 GB in 40 s.
// Now exit 2 once the answer passes the largest a GCS answer can be, naming it.
TEST_F(Serve, TheGcsCommandRefusesAnAnswerBeyondTheLargest) {
  const int listener = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(listener, reinterpret_cast<sockaddr*>(&sa), sizeof sa), 0);
  ASSERT_EQ(::listen(listener, 1), 0);
  socklen_t len = sizeof sa;
  ::getsockname(listener, reinterpret_cast<sockaddr*>(&sa), &len);
  std::thread endless([listener] {
    const int fd = ::accept(listener, nullptr, nullptr);
    const std::string chunk(65536, '7');
    while (fd >= 0 && ::send(fd, chunk.data(), chunk.size(), MSG_NOSIGNAL) > 0) {
    }
    if (fd >= 0)
      ::close(fd);
  });
  const Spawned client = spawn({"gcs", "--port", std::to_string(ntohs(sa.sin_port)), "POS?"},
                               path("gcs.txt"), path("gcs_err.txt"));
  EXPECT_EQ(wait_exit(client), 2);
  EXPECT_NE(slurp(path("gcs_err.txt")).find("exceeds 1180672 bytes"), std::string::npos)
      << slurp(path("gcs_err.txt"));
  endless.join();
  ::close(listener);
}

// Waits for s to exit, at most limit_s (a hang guard, not a timing assertion: the cases below end
// in about 2 s); -2 and SIGKILL when it did not.
int wait_exit_or_kill(const Spawned& s, int limit_s) {
  for (int i = 0; i < limit_s * 100; ++i) {
    int status = 0;
    if (waitpid(s.pid, &status, WNOHANG) == s.pid)
      return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(s.pid, SIGKILL);
  wait_exit(s);
  return -2;
}

// A twin of 2e10 Hz physics once spun for minutes past --duration-s and SIGTERM. Such a rate
// is refused by file and key; the heaviest accepted one (1e7 Hz, 10 000 physics steps per 1 ms
// tick) honours both.
TEST_F(Serve, HeaviestAcceptedTwinHonoursDurationAndSigterm) {
  const std::string too_fast = write("too_fast.toml", "[twin]\nphysics_rate_Hz = 2e10\n");
  const Spawned refused = spawn({"serve", "--port", "0", "--config", too_fast, "--duration-s", "1"},
                                path("o.txt"), path("e.txt"));
  EXPECT_EQ(wait_exit_or_kill(refused, 60), 2);
  EXPECT_NE(slurp(path("e.txt")).find(too_fast + ":2:19: twin.physics_rate_Hz"), std::string::npos)
      << slurp(path("e.txt"));

  const std::string heavy = write("heavy.toml", "[twin]\nphysics_rate_Hz = 1e7\n");
  ASSERT_NE(start({"--config", heavy, "--duration-s", "1"}), 0);
  EXPECT_EQ(wait_exit_or_kill(server_, 120), 0) << slurp(path("err.txt"));
  server_.pid = -1;
  const std::string out = slurp(path("out.txt"));
  EXPECT_NE(out.find("\"stop_reason\": \"duration\""), std::string::npos) << out;

  ASSERT_NE(start({"--config", heavy}), 0);
  kill(server_.pid, SIGTERM);
  EXPECT_EQ(wait_exit_or_kill(server_, 120), 0) << slurp(path("err.txt"));
  server_.pid = -1;
  EXPECT_NE(slurp(path("out.txt")).find("\"stop_reason\": \"SIGTERM\""), std::string::npos);
}

// The installation's [safety] is applied and shown at start-up and in the summary; the command
// line's --max-overruns (start() gives 1000000) overrides its overrun count.
TEST_F(Serve, SafetySectionIsAppliedAndShown) {
  const std::string site =
      write("site.toml", "[safety]\noutput_max_V = 8.0\nmax_consecutive_overruns = 5\n");
  ASSERT_NE(start({"--config", site, "--duration-s", "0.2"}), 0);
  EXPECT_EQ(wait_exit_or_kill(server_, 120), 0) << slurp(path("err.txt"));
  server_.pid = -1;
  const std::string out = slurp(path("out.txt"));
  EXPECT_NE(out.find("safety (" + site + " [safety]): outputs 0 to 8 V"), std::string::npos) << out;
  const nlohmann::json j = nlohmann::json::parse(out.substr(out.find("\n{") + 1));
  EXPECT_EQ(j.at("safety").at("output_max_V"), 8.0);
  EXPECT_EQ(j.at("safety").at("max_consecutive_overruns"), 1000000);
}

// serve prints each fault on stderr when it latches, while it runs on, and its
// summaries (JSON and text) name every fault: rule, channel, time, value and limit.
TEST_F(Serve, EveryFaultIsPrintedWhenItLatchesAndNamedInTheSummary) {
  ASSERT_NE(start({"--fault", "sgs-open@0.3:1"}), 0);
  const std::string line_start = "piezoshift: fault latched at tick ";
  std::string err;
  for (int i = 0; i < 3000 && err.find(line_start) == std::string::npos; ++i) {  // up to 30 s
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    err = slurp(path("err.txt"));
  }
  ASSERT_NE(err.find(line_start), std::string::npos) << err;
  EXPECT_EQ(kill(server_.pid, 0), 0) << "still serving";
  EXPECT_NE(err.find(": sgs-rail on channel 1, value 10 V, limit 9.98 V; outputs ramping to 0 V\n"),
            std::string::npos)
      << err;
  const nlohmann::json j = stop();
  ASSERT_EQ(j.at("faults_latched").size(), 1U) << j.dump();
  const nlohmann::json& f = j.at("faults_latched")[0];
  EXPECT_EQ(f.at("reason"), "sgs-rail");
  EXPECT_EQ(f.at("channel"), 1);
  // The first tick at or after 0.3 s (later when slots were skipped on a loaded machine).
  EXPECT_GE(f.at("time_s").get<double>(), 0.3);
  EXPECT_LT(f.at("time_s").get<double>(), 0.4);
  EXPECT_DOUBLE_EQ(f.at("value").get<double>(), 10.0 - 20.0 / 65536.0);  // the ADC's top code
  EXPECT_DOUBLE_EQ(f.at("limit").get<double>(), 9.98);
  EXPECT_EQ(f.at("unit"), "V");
  EXPECT_EQ(j.at("faults_latched_count"), 1);

  const Spawned text = spawn({"serve", "--port", "0", "--max-overruns", "1000000", "--calibration",
                              calibration_, "--duration-s", "0.5", "--fault", "sgs-open@0.2:3"},
                             path("text.txt"), path("text_err.txt"));
  EXPECT_EQ(wait_exit_or_kill(text, 120), 0) << slurp(path("text_err.txt"));
  const std::string out = slurp(path("text.txt"));
  const std::size_t at = out.find("fault 1        sgs-rail on channel 3 at t = 0.2");
  ASSERT_NE(at, std::string::npos) << out;
  EXPECT_NE(out.find("value 10 V, limit 9.98 V\n", at), std::string::npos) << out;
}

TEST_F(Serve, RefusesARemoteAddressWithoutAllowRemoteAndBadInputWithExit2) {
  const auto refused = [&](std::vector<std::string> args, const std::string& piece) {
    const Spawned s = spawn(args, path("o.txt"), path("e.txt"));
    EXPECT_EQ(wait_exit(s), 2) << args[1];
    const std::string err = slurp(path("e.txt"));
    EXPECT_NE(err.find(piece), std::string::npos) << err;
  };
  refused({"serve", "--bind", "0.0.0.0", "--port", "0"}, "--allow-remote");
  refused({"serve", "--bind", "not-an-address", "--port", "0"}, "not-an-address");
  refused({"serve", "--port", "70000"}, "--port 70000");
  refused({"serve", "--port", "0", "--calibration", path("missing.toml")}, "missing.toml");
  refused({"serve", "--port", "0", "--daq", "comedi:/dev/comedi_missing"}, "comedi_missing");
  // A config valid at its own 1 kHz but not at the loop's 3 kHz (21 kHz physics is no multiple of
  // the interferometer's 1 kHz): the message names the rate and the file, not only a key.
  const std::string cfg = write("twin.toml", "[twin]\nphysics_rate_Hz = 20000\n");
  refused(
      {"serve", "--port", "0", "--rate-hz", "3000", "--config", cfg, "--calibration", calibration_},
      "sim at 3000 Hz: the twin of " + cfg + " cannot be built");
}

}  // namespace
