// `piezoshift run` end to end: the program is spawned, as an operator would run it. The signal
// tests run on the real clock (the point is a live process); they lift the overrun rule so a
// loaded test machine cannot turn them into a fault run: timing is not what they test.
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/spawned_process.hpp"

namespace {

namespace fs = std::filesystem;
using piezoshift::testing::slurp;
using piezoshift::testing::spawn;
using piezoshift::testing::Spawned;
using piezoshift::testing::wait_exit;

// Complete lines only: a trailing fragment without its newline is dropped and reported.
std::vector<std::string> lines(const std::string& text, bool* partial_tail = nullptr) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t nl = text.find('\n'); nl != std::string::npos; nl = text.find('\n', start)) {
    out.push_back(text.substr(start, nl - start));
    start = nl + 1;
  }
  if (partial_tail)
    *partial_tail = start < text.size();
  return out;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ','))
    f.push_back(cell);
  return f;
}

// Polls (no timing assert) until the log has at least n complete lines; false after 60 s.
bool wait_for_lines(const std::string& path, std::size_t n) {
  for (int i = 0; i < 6000; ++i) {
    if (lines(slurp(path)).size() >= n)
      return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

using RunCommand = piezoshift::testing::TempDirTest;

// Checks a log's data rows: right width, consecutive ticks from 0, numbers everywhere.
void expect_valid_log(const std::vector<std::string>& rows, std::size_t width) {
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const std::vector<std::string> f = split(rows[i]);
    ASSERT_EQ(f.size(), width) << "line " << i + 1 << ": " << rows[i];
    ASSERT_EQ(std::stoull(f[0]), i - 1) << "line " << i + 1;
    for (const std::string& cell : f) {
      std::size_t used = 0;
      const double v = std::stod(cell, &used);
      ASSERT_EQ(used, cell.size()) << "line " << i + 1 << ": '" << cell << "'";
      (void)v;
    }
  }
}

TEST_F(RunCommand, MissingComediDeviceExits2NamingThePath) {
  const std::string dev = path("no-such-comedi0");
  const Spawned s =
      spawn({"run", "--daq", "comedi:" + dev, "--duration-s", "1"}, path("out"), path("err"));
  EXPECT_EQ(wait_exit(s), 2);
  const std::string err = slurp(path("err"));
  EXPECT_NE(err.find(dev), std::string::npos) << err;
  EXPECT_NE(err.find("cannot open"), std::string::npos) << err;
}

TEST_F(RunCommand, BadInputExits2) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"run", "--duration-s", "1", "--rate-hz", "500"},
        std::vector<std::string>{"run", "--duration-s", "1", "--step-um", "20"},
        std::vector<std::string>{"run", "--duration-s", "1", "--fault", "sgs-melt@1"},
        std::vector<std::string>{"run", "--duration-s", "1", "--daq", "ni"}}) {
    const Spawned s = spawn(args, path("out"), path("err"));
    EXPECT_EQ(wait_exit(s), 2) << args[3] << " " << args[4] << ": " << slurp(path("err"));
  }
}

TEST_F(RunCommand, FreeRunStepJsonSummary) {
  const Spawned s = spawn(
      {"run", "--daq", "sim", "--free-run", "--step-um", "6", "--duration-s", "0.5", "--json"},
      path("out"), path("err"));
  ASSERT_EQ(wait_exit(s), 0) << slurp(path("err"));
  const nlohmann::json j = nlohmann::json::parse(slurp(path("out")));
  EXPECT_GE(j["ticks"].get<int>(), 500);
  EXPECT_EQ(j["period_error_p999_us"].get<double>(), 0.0) << "simulated clock";
  EXPECT_EQ(j["overruns"].get<int>(), 0);
  EXPECT_FALSE(j["fault_detected"].get<bool>());
  EXPECT_TRUE(j["detect_latency_ticks"].is_null());
  EXPECT_EQ(j["stop_reason"], "duration");
  EXPECT_LE(j["max_output_V"].get<double>(), 10.0);
  EXPECT_LE(j["max_output_slew_V_per_ms"].get<double>(), 1.5 + 1e-9);
}

TEST_F(RunCommand, InjectedFaultIsReportedWithItsLatencyAndExit3) {
  const Spawned s = spawn({"run", "--daq", "sim", "--free-run", "--step-um", "6", "--duration-s",
                           "0.5", "--fault", "sgs-open@0.2:2", "--json", "--log", path("log.csv")},
                          path("out"), path("err"));
  ASSERT_EQ(wait_exit(s), 3) << slurp(path("err"));
  const nlohmann::json j = nlohmann::json::parse(slurp(path("out")));
  EXPECT_TRUE(j["fault_detected"].get<bool>());
  EXPECT_EQ(j["fault_reason"], "sgs-rail");
  EXPECT_EQ(j["fault_channel"], 2);
  EXPECT_EQ(j["fault_tick"], 200);
  EXPECT_EQ(j["detect_latency_ticks"], 0);
  EXPECT_EQ(j["stop_reason"], "fault");
  EXPECT_LE(j["max_output_V"].get<double>(), 10.0);
  EXPECT_LE(j["max_output_slew_V_per_ms"].get<double>(), 1.5 + 1e-9);
  EXPECT_NE(slurp(path("err")).find("fault latched at tick 200"), std::string::npos);
  // The log holds every tick, the last with all outputs at 0 V and the fault code.
  const std::vector<std::string> rows = lines(slurp(path("log.csv")));
  ASSERT_EQ(rows.size(), j["ticks"].get<std::size_t>() + 1);
  const std::vector<std::string> header = split(rows[0]);
  expect_valid_log(rows, header.size());
  const std::vector<std::string> last = split(rows.back());
  for (const char* col : {"ao1_V", "ao2_V", "ao3_V"}) {
    const auto c = std::find(header.begin(), header.end(), col) - header.begin();
    EXPECT_EQ(std::stod(last[static_cast<std::size_t>(c)]), 0.0) << col;
  }
}

// Every fault is named by its rule, channel, time and the value that tripped it
// against its limit, with their unit: on stderr as it latches (no --log needed) and in both
// summaries.
TEST_F(RunCommand, EveryFaultIsNamedWithItsRuleChannelTimeValueAndLimit) {
  const std::vector<std::string> args{"run", "--daq",        "sim", "--free-run", "--step-um",
                                      "6",   "--duration-s", "0.5", "--fault",    "sgs-open@0.2:2"};
  const Spawned text = spawn(args, path("out"), path("err"));
  ASSERT_EQ(wait_exit(text), 3) << slurp(path("err"));
  EXPECT_NE(slurp(path("out"))
                .find("FAULT          sgs-rail on channel 2 at t = 0.2000 s (tick "
                      "200): value 10 V, limit 9.98 V, 0 ticks after injection\n"),
            std::string::npos)
      << slurp(path("out"));
  EXPECT_NE(slurp(path("err"))
                .find("piezoshift: fault latched at tick 200 (t = 0.2000 s): "
                      "sgs-rail on channel 2, value 10 V, limit 9.98 V; outputs "
                      "ramping to 0 V\n"),
            std::string::npos)
      << slurp(path("err"));

  std::vector<std::string> json_args = args;
  json_args.push_back("--json");
  const Spawned json = spawn(json_args, path("out.json"), path("err2"));
  ASSERT_EQ(wait_exit(json), 3) << slurp(path("err2"));
  const nlohmann::json j = nlohmann::json::parse(slurp(path("out.json")));
  ASSERT_EQ(j["faults_latched"].size(), 1U) << j.dump();
  const nlohmann::json& f = j["faults_latched"][0];
  EXPECT_EQ(f["reason"], "sgs-rail");
  EXPECT_EQ(f["channel"], 2);
  EXPECT_EQ(f["tick"], 200);
  EXPECT_DOUBLE_EQ(f["time_s"].get<double>(), 0.2);
  // The open bridge's 12 V, clipped by the ADC at its top code: 10 V less one LSB (20 V / 2^16).
  EXPECT_DOUBLE_EQ(f["value"].get<double>(), 10.0 - 20.0 / 65536.0);
  EXPECT_DOUBLE_EQ(f["limit"].get<double>(), 9.98);
  EXPECT_EQ(f["unit"], "V");
  EXPECT_FALSE(f.contains("load_average")) << "only an overrun trip names the load";
}

// On the twin a late host is counted and reported, not a fault, unless [safety] asks
// (trip_on_overruns: 0 never, 1 always, 2 on hardware only, the default). The burst makes five
// ticks of 1.5 periods each on the simulated clock: deterministic lateness.
TEST_F(RunCommand, OnTheTwinOverrunsAreCountedNotTrippedByDefault) {
  const Spawned s = spawn({"run", "--daq", "sim", "--free-run", "--step-um", "6", "--duration-s",
                           "0.5", "--fault", "overrun-burst@0.2", "--json"},
                          path("out"), path("err"));
  ASSERT_EQ(wait_exit(s), 0) << slurp(path("err"));
  const nlohmann::json j = nlohmann::json::parse(slurp(path("out")));
  EXPECT_FALSE(j["fault_detected"].get<bool>()) << j.dump();
  EXPECT_EQ(j["faults_latched"].size(), 0U);
  EXPECT_EQ(j["overruns"], 5);
  EXPECT_EQ(j["max_consecutive_overruns"], 5);
  EXPECT_EQ(j["safety"]["trip_on_overruns"], 0) << "resolved for the twin";
  EXPECT_EQ(j["stop_reason"], "duration");

  const std::string bad_site = write("bad.toml", "[safety]\ntrip_on_overruns = 3\n");
  const Spawned bad =
      spawn({"run", "--daq", "sim", "--free-run", "--duration-s", "0.1", "--config", bad_site},
            path("out2"), path("err2"));
  EXPECT_EQ(wait_exit(bad), 2);
  EXPECT_NE(slurp(path("err2")).find("trip_on_overruns"), std::string::npos) << slurp(path("err2"));
}

// An overrun trip names its rule (the count against its limit), the worst lateness and
// the machine's load. On the simulated clock the burst's ticks each take 1.5 periods: 500 us
// past the next deadline, three in a row. The twin trips on them only when [safety] asks.
TEST_F(RunCommand, AnOverrunTripNamesItsRuleLatenessAndTheLoad) {
  const std::string site = write("site.toml", "[safety]\ntrip_on_overruns = 1\n");
  const Spawned s = spawn({"run", "--daq", "sim", "--free-run", "--step-um", "6", "--duration-s",
                           "0.5", "--fault", "overrun-burst@0.2", "--json", "--config", site},
                          path("out"), path("err"));
  ASSERT_EQ(wait_exit(s), 3) << slurp(path("err"));
  const nlohmann::json j = nlohmann::json::parse(slurp(path("out")));
  ASSERT_EQ(j["faults_latched"].size(), 1U) << j.dump();
  const nlohmann::json& f = j["faults_latched"][0];
  EXPECT_EQ(f["reason"], "overruns");
  EXPECT_TRUE(f["channel"].is_null());
  EXPECT_EQ(f["value"], 3.0);
  EXPECT_EQ(f["limit"], 3.0);
  EXPECT_EQ(f["unit"], "ticks");
  EXPECT_DOUBLE_EQ(f["worst_lateness_us"].get<double>(), 500.0);
  const std::regex load(R"([0-9]+\.[0-9]+ [0-9]+\.[0-9]+ [0-9]+\.[0-9]+)");
  EXPECT_TRUE(std::regex_match(f["load_average"].get<std::string>(), load)) << f.dump();
  const std::string err = slurp(path("err"));
  EXPECT_NE(err.find("overruns, 3 consecutive ticks overran (limit 3), the worst ended 500.0 us "
                     "after the next deadline; load average " +
                     f["load_average"].get<std::string>()),
            std::string::npos)
      << err;
}

TEST_F(RunCommand, SigkillMidRunLeavesAValidCsvUpToTheLastFlush) {
  const std::string log = path("killed.csv");
  const Spawned s = spawn({"run", "--daq", "sim", "--step-um", "5", "--duration-s", "60", "--cpu",
                           "-2", "--max-overruns", "1000000", "--log", log},
                          path("out"), path("err"));
  ASSERT_TRUE(wait_for_lines(log, 400)) << slurp(path("err"));
  kill(s.pid, SIGKILL);
  bool signaled = false;
  int signo = 0;
  wait_exit(s, &signaled, &signo);
  ASSERT_TRUE(signaled);
  EXPECT_EQ(signo, SIGKILL);
  bool partial = false;
  const std::vector<std::string> rows = lines(slurp(log), &partial);
  ASSERT_GE(rows.size(), 400U);
  const std::vector<std::string> header = split(rows[0]);
  EXPECT_EQ(header[0], "tick");
  expect_valid_log(rows, header.size());
  // Lines are written whole: a partial tail can only come from a kill inside a write(2).
  EXPECT_FALSE(partial) << "the log ends inside a line";
}

TEST_F(RunCommand, SigtermRampsToZeroAndClosesTheLog) {
  const std::string log = path("term.csv");
  const Spawned s = spawn({"run", "--daq", "sim", "--step-um", "8", "--duration-s", "60", "--cpu",
                           "-2", "--max-overruns", "1000000", "--log", log, "--json"},
                          path("out"), path("err"));
  ASSERT_TRUE(wait_for_lines(log, 600)) << slurp(path("err"));
  kill(s.pid, SIGTERM);
  ASSERT_EQ(wait_exit(s), 0) << slurp(path("err"));
  const nlohmann::json j = nlohmann::json::parse(slurp(path("out")));
  EXPECT_EQ(j["stop_reason"], "SIGTERM");
  EXPECT_FALSE(j["fault_detected"].get<bool>()) << j.dump();
  bool partial = false;
  const std::string text = slurp(log);
  const std::vector<std::string> rows = lines(text, &partial);
  EXPECT_FALSE(partial);
  ASSERT_EQ(rows.size(), j["ticks"].get<std::size_t>() + 1) << "every tick logged, then closed";
  EXPECT_EQ(j["log"]["records_written"], j["ticks"]);
  const std::vector<std::string> header = split(rows[0]);
  expect_valid_log(rows, header.size());
  const auto col = [&header](const char* name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  // Walk back from the end: the ramp runs at the safe 0.5 V/ms and ends at 0 V, stopped (2).
  const std::vector<std::string> last = split(rows.back());
  EXPECT_EQ(std::stoi(last[col("state")]), 2);
  double top = 0.0;
  for (std::size_t i = rows.size() - 1; i > 1; --i) {
    const std::vector<std::string> a = split(rows[i]);
    const std::vector<std::string> b = split(rows[i - 1]);
    if (std::stoi(b[col("state")]) == 0)
      break;  // reached the last running tick
    for (const char* c : {"ao1_V", "ao2_V", "ao3_V"}) {
      const double step = std::stod(b[col(c)]) - std::stod(a[col(c)]);
      EXPECT_LE(std::fabs(step), 0.5 + 1e-6) << "line " << i + 1;  // 9 digits in the CSV
      top = std::max(top, std::stod(b[col(c)]));
    }
  }
  EXPECT_GT(top, 3.0) << "the outputs were ramped down from where the step had put them";
  for (const char* c : {"ao1_V", "ao2_V", "ao3_V"})
    EXPECT_EQ(std::stod(last[col(c)]), 0.0);
}

}  // namespace
