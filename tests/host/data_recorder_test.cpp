// The GCS data recorder: table set-up and its error numbers, the record rate and capacity, the
// restart trigger, and DRR?'s header-then-columns text parsed back.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "piezoshift/host/data_recorder.hpp"

namespace piezoshift::host {
namespace {

// Cycle k's input: every signal a distinct, non-round function of k.
RecorderInput input_at(int k) {
  RecorderInput in;
  for (std::size_t i = 0; i < 3; ++i) {
    const double d = static_cast<double>(i);
    in.target[i] = 1.0 + 0.123456789 * k + 10.0 * d;
    in.position[i] = 0.5 + 0.111111111 * k - 3.0 * d;
    in.interferometer[i] = 0.25 + 0.3 * k + d;
    in.channel_V[i] = 20.0 + 0.7 * k + d;
    in.sensor_um[i] = 2.0 + 0.01 * k + 0.5 * d;
  }
  return in;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t lf = text.find('\n', start);
    if (lf == std::string::npos) {
      lines.push_back(text.substr(start));
      break;
    }
    lines.push_back(text.substr(start, lf - start + 1));  // with its LF
    start = lf + 1;
  }
  return lines;
}

struct Parsed {
  std::map<std::string, std::string> header;
  std::vector<std::vector<double>> rows;
  bool framing_ok = true;
  bool has_end = false;
};

// Parses DRR?'s answer; checks GCS framing (" \n" on every line but the last, "\n" on the last).
Parsed parse(const std::string& text) {
  Parsed p;
  const std::vector<std::string> lines = split_lines(text);
  bool in_header = true;
  for (std::size_t l = 0; l < lines.size(); ++l) {
    std::string line = lines[l];
    const bool last = l + 1 == lines.size();
    if (last) {
      if (line.size() < 1 || line.back() != '\n' ||
          (line.size() >= 2 && line[line.size() - 2] == ' '))
        p.framing_ok = false;
      line.pop_back();
    } else {
      if (line.size() < 2 || line.substr(line.size() - 2) != " \n")
        p.framing_ok = false;
      line.resize(line.size() - 2);
    }
    if (in_header) {
      if (line == "# END_HEADER") {
        in_header = false;
        p.has_end = true;
        continue;
      }
      const std::size_t eq = line.find(" = ");
      if (line.rfind("# ", 0) == 0 && eq != std::string::npos)
        p.header[line.substr(2, eq - 2)] = line.substr(eq + 3);
      continue;
    }
    std::vector<double> row;
    const char* c = line.c_str();
    char* end = nullptr;
    for (double v = std::strtod(c, &end); end != c; v = std::strtod(c, &end)) {
      row.push_back(v);
      c = end;
    }
    p.rows.push_back(row);
  }
  return p;
}

TEST(DataRecorderTest, DefaultTablesAreTargetAndPositionOfZ) {
  const DataRecorder r;
  EXPECT_EQ(r.describe_table(1), "Z 1");
  EXPECT_EQ(r.describe_table(2), "Z 2");
  for (int t = 3; t <= DataRecorder::kTables; ++t)
    EXPECT_EQ(r.describe_table(t), "0 0") << t;
  EXPECT_EQ(r.rate(), 1);
  EXPECT_EQ(r.points(), 0u);
  EXPECT_TRUE(r.table_exists(1));
  EXPECT_TRUE(r.table_exists(8));
  EXPECT_FALSE(r.table_exists(0));
  EXPECT_FALSE(r.table_exists(9));
}

TEST(DataRecorderTest, ConfigureErrors) {
  DataRecorder r;
  EXPECT_EQ(r.configure(0, "Z", 1), GcsError::kNoRecordTable);
  EXPECT_EQ(r.configure(9, "Z", 1), GcsError::kNoRecordTable);
  EXPECT_EQ(r.configure(1, "Z", 5), GcsError::kNoRecordOption);
  EXPECT_EQ(r.configure(1, "Z", -1), GcsError::kNoRecordOption);
  EXPECT_EQ(r.configure(1, "Q", 2), GcsError::kInvalidAxis);
  EXPECT_EQ(r.configure(1, "1", 2), GcsError::kInvalidAxis);  // option 2 wants an axis
  EXPECT_EQ(r.configure(1, "4", 17), GcsError::kParamOutOfRange);
  EXPECT_EQ(r.configure(1, "0", 7), GcsError::kParamOutOfRange);
  EXPECT_EQ(r.configure(1, "Z", 7), GcsError::kParamOutOfRange);  // option 7 wants a channel
  EXPECT_EQ(r.configure(1, "12", 7), GcsError::kParamOutOfRange);
  // A refused set-up changes nothing.
  EXPECT_EQ(r.describe_table(1), "Z 1");
}

TEST(DataRecorderTest, ConfigureAndDescribe) {
  DataRecorder r;
  EXPECT_EQ(r.configure(3, "U", 3), GcsError::kNone);
  EXPECT_EQ(r.describe_table(3), "U 3");
  EXPECT_EQ(r.configure(4, "2", 7), GcsError::kNone);
  EXPECT_EQ(r.describe_table(4), "2 7");
  EXPECT_EQ(r.configure(5, "3", 17), GcsError::kNone);
  EXPECT_EQ(r.describe_table(5), "3 17");
  EXPECT_EQ(r.configure(8, "V", 90), GcsError::kNone);
  EXPECT_EQ(r.describe_table(8), "V 90");
  EXPECT_EQ(r.configure(1, "anything", 0), GcsError::kNone);
  EXPECT_EQ(r.describe_table(1), "0 0");
}

TEST(DataRecorderTest, RateRecordsEveryNthCycle) {
  for (int n = 1; n <= 10; ++n) {
    DataRecorder r;
    ASSERT_EQ(r.set_rate(3), GcsError::kNone);
    for (int k = 0; k < n; ++k)
      r.record(input_at(k));
    EXPECT_EQ(r.points(), static_cast<std::size_t>((n + 2) / 3)) << n;  // ceil(n / 3)
  }
  // Cycles 0, 3, 6, 9 are the ones kept: table 1 (Z target) shows 1 + 0.123456789 k.
  DataRecorder r;
  ASSERT_EQ(r.set_rate(3), GcsError::kNone);
  EXPECT_EQ(r.rate(), 3);
  for (int k = 0; k < 10; ++k)
    r.record(input_at(k));
  std::string text;
  ASSERT_EQ(r.read(1, -1, {1}, 1e-3, text), GcsError::kNone);
  const Parsed p = parse(text);
  ASSERT_EQ(p.rows.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i)
    EXPECT_NEAR(p.rows[i].at(0), 1.0 + 0.123456789 * 3.0 * static_cast<double>(i), 1e-8);
  EXPECT_EQ(p.header.at("SAMPLE_TIME"), "0.003");
}

TEST(DataRecorderTest, RateLimits) {
  DataRecorder r;
  EXPECT_EQ(r.set_rate(0), GcsError::kParamOutOfRange);
  EXPECT_EQ(r.set_rate(-3), GcsError::kParamOutOfRange);
  EXPECT_EQ(r.set_rate(DataRecorder::kMaxRate + 1LL), GcsError::kParamOutOfRange);
  EXPECT_EQ(r.rate(), 1);
  EXPECT_EQ(r.set_rate(DataRecorder::kMaxRate), GcsError::kNone);
  EXPECT_EQ(r.rate(), DataRecorder::kMaxRate);
}

TEST(DataRecorderTest, StopsWhenFull) {
  DataRecorder r;
  for (std::size_t k = 0; k < DataRecorder::kPoints + 100; ++k)
    r.record(input_at(static_cast<int>(k)));
  EXPECT_EQ(r.points(), DataRecorder::kPoints);
  // The first kPoints are held, not the last.
  std::string text;
  ASSERT_EQ(r.read(static_cast<long long>(DataRecorder::kPoints), 1, {1}, 1e-3, text),
            GcsError::kNone);
  const Parsed p = parse(text);
  ASSERT_EQ(p.rows.size(), 1u);
  EXPECT_NEAR(p.rows[0].at(0), 1.0 + 0.123456789 * (DataRecorder::kPoints - 1.0), 1e-5);
}

TEST(DataRecorderTest, RestartClearsAndSetUpChangesRestart) {
  DataRecorder r;
  for (int k = 0; k < 5; ++k)
    r.record(input_at(k));
  EXPECT_EQ(r.points(), 5u);
  r.restart();
  EXPECT_EQ(r.points(), 0u);
  for (int k = 0; k < 3; ++k)
    r.record(input_at(k));
  EXPECT_EQ(r.points(), 3u);
  ASSERT_EQ(r.configure(3, "Z", 3), GcsError::kNone);
  EXPECT_EQ(r.points(), 0u);
  r.record(input_at(0));
  ASSERT_EQ(r.set_rate(2), GcsError::kNone);
  EXPECT_EQ(r.points(), 0u);
  // A refused set-up is no trigger.
  r.record(input_at(0));
  EXPECT_EQ(r.configure(9, "Z", 1), GcsError::kNoRecordTable);
  EXPECT_EQ(r.set_rate(0), GcsError::kParamOutOfRange);
  EXPECT_EQ(r.points(), 1u);
}

TEST(DataRecorderTest, ReadGivesHeaderThenColumns) {
  DataRecorder r;
  ASSERT_EQ(r.configure(3, "U", 3), GcsError::kNone);
  ASSERT_EQ(r.configure(4, "2", 7), GcsError::kNone);
  ASSERT_EQ(r.configure(5, "3", 17), GcsError::kNone);
  ASSERT_EQ(r.configure(6, "V", 90), GcsError::kNone);
  for (int k = 0; k < 6; ++k)
    r.record(input_at(k));

  std::string text;
  ASSERT_EQ(r.read(1, -1, {}, 2.5e-4, text), GcsError::kNone);
  const Parsed p = parse(text);
  EXPECT_TRUE(p.framing_ok) << text;
  EXPECT_TRUE(p.has_end) << text;
  EXPECT_EQ(text.rfind("# ", 0), 0u);
  EXPECT_EQ(p.header.at("DIM"), "6");
  EXPECT_EQ(p.header.at("NDATA"), "6");
  EXPECT_EQ(p.header.at("SEPARATOR"), "32");
  EXPECT_EQ(p.header.at("SAMPLE_TIME"), "0.00025");
  EXPECT_EQ(p.header.at("NAME0"), "Target position of axis Z (um)");
  EXPECT_EQ(p.header.at("NAME1"), "Current position of axis Z (um)");
  EXPECT_EQ(p.header.at("NAME2"), "Position error of axis U (urad)");
  EXPECT_EQ(p.header.at("NAME3"), "Voltage of output channel 2 (V)");
  EXPECT_EQ(p.header.at("NAME4"), "Sensor of input channel 3 (um)");
  EXPECT_EQ(p.header.at("NAME5"), "Interferometer position of axis V (urad)");
  EXPECT_EQ(p.header.count("NAME6"), 0u);
  ASSERT_EQ(p.rows.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    const RecorderInput in = input_at(k);
    const std::vector<double>& row = p.rows[static_cast<std::size_t>(k)];
    ASSERT_EQ(row.size(), 6u);
    const double expected[6] = {in.target[0],    in.position[0],  in.target[1] - in.position[1],
                                in.channel_V[1], in.sensor_um[2], in.interferometer[2]};
    for (std::size_t c = 0; c < 6; ++c)  // %.9g: 9 significant digits
      EXPECT_NEAR(row[c], expected[c], 5e-9 * std::fabs(expected[c]) + 1e-15) << k << " " << c;
  }
}

TEST(DataRecorderTest, ReadWindowAndTableSelection) {
  DataRecorder r;
  for (int k = 0; k < 10; ++k)
    r.record(input_at(k));
  std::string text;
  ASSERT_EQ(r.read(4, 3, {2, 1}, 1e-3, text), GcsError::kNone);
  const Parsed p = parse(text);
  EXPECT_TRUE(p.framing_ok) << text;
  EXPECT_EQ(p.header.at("DIM"), "2");
  EXPECT_EQ(p.header.at("NDATA"), "3");
  EXPECT_EQ(p.header.at("NAME0"), "Current position of axis Z (um)");
  EXPECT_EQ(p.header.at("NAME1"), "Target position of axis Z (um)");
  ASSERT_EQ(p.rows.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const RecorderInput in = input_at(3 + i);
    EXPECT_NEAR(p.rows[static_cast<std::size_t>(i)].at(0), in.position[0], 1e-8);
    EXPECT_NEAR(p.rows[static_cast<std::size_t>(i)].at(1), in.target[0], 1e-8);
  }
  // From 8 to the end: 3 points; the whole table exactly: fine.
  ASSERT_EQ(r.read(8, -1, {1}, 1e-3, text), GcsError::kNone);
  EXPECT_EQ(parse(text).rows.size(), 3u);
  ASSERT_EQ(r.read(1, 10, {1}, 1e-3, text), GcsError::kNone);
  EXPECT_EQ(parse(text).rows.size(), 10u);
  // Nothing left from 11: a header alone, still framed.
  ASSERT_EQ(r.read(11, -1, {1}, 1e-3, text), GcsError::kNone);
  const Parsed empty = parse(text);
  EXPECT_TRUE(empty.framing_ok) << text;
  EXPECT_EQ(empty.header.at("NDATA"), "0");
  EXPECT_EQ(empty.rows.size(), 0u);
  EXPECT_EQ(text.substr(text.size() - 13), "# END_HEADER\n");
}

TEST(DataRecorderTest, ReadErrors) {
  DataRecorder r;
  for (int k = 0; k < 10; ++k)
    r.record(input_at(k));
  std::string text = "stale";
  EXPECT_EQ(r.read(1, 11, {1}, 1e-3, text), GcsError::kNotEnoughData);
  EXPECT_EQ(text, "");
  EXPECT_EQ(r.read(10, 2, {1}, 1e-3, text), GcsError::kNotEnoughData);
  EXPECT_EQ(r.read(12, -1, {1}, 1e-3, text), GcsError::kNotEnoughData);
  EXPECT_EQ(r.read(1, -1, {3}, 1e-3, text), GcsError::kTableDeactivated);
  EXPECT_EQ(r.read(1, -1, {1, 3}, 1e-3, text), GcsError::kTableDeactivated);
  EXPECT_EQ(r.read(1, -1, {9}, 1e-3, text), GcsError::kNoRecordTable);
  EXPECT_EQ(r.read(1, -1, {0}, 1e-3, text), GcsError::kNoRecordTable);
  EXPECT_EQ(r.read(0, -1, {1}, 1e-3, text), GcsError::kParamOutOfRange);
  EXPECT_EQ(r.read(-5, 1, {1}, 1e-3, text), GcsError::kParamOutOfRange);
  EXPECT_EQ(text, "");
  // Every table off: nothing to read.
  ASSERT_EQ(r.configure(1, "Z", 0), GcsError::kNone);
  ASSERT_EQ(r.configure(2, "Z", 0), GcsError::kNone);
  EXPECT_EQ(r.read(1, -1, {}, 1e-3, text), GcsError::kTableDeactivated);
}

// A count near the largest long long once overflowed start - 1 + count and answered a header
// of 9223372036854775807 points; a table named twice doubled the columns.
TEST(DataRecorderTest, ReadRefusesHugeCountsAndRepeatedTables) {
  DataRecorder r;
  for (int k = 0; k < 10; ++k)
    r.record(input_at(k));
  constexpr long long kMax = std::numeric_limits<long long>::max();
  std::string text = "stale";
  EXPECT_EQ(r.read(2, kMax, {1}, 1e-3, text), GcsError::kNotEnoughData);
  EXPECT_EQ(text, "");
  EXPECT_EQ(r.read(11, kMax, {1}, 1e-3, text), GcsError::kNotEnoughData);
  EXPECT_EQ(r.read(kMax, 1, {1}, 1e-3, text), GcsError::kNotEnoughData);
  EXPECT_EQ(r.read(kMax, -1, {1}, 1e-3, text), GcsError::kNotEnoughData);
  EXPECT_EQ(r.read(1, kMax, {}, 1e-3, text), GcsError::kNotEnoughData);
  EXPECT_EQ(r.read(1, -1, {1, 2, 1}, 1e-3, text), GcsError::kParamSyntax);
  EXPECT_EQ(r.read(1, -1, {2, 2}, 1e-3, text), GcsError::kParamSyntax);
  EXPECT_EQ(r.read(1, -1, std::vector<int>(2000, 1), 1e-3, text), GcsError::kParamSyntax);
  EXPECT_EQ(text, "");
  // The last point alone, and no point after the last, still answer.
  ASSERT_EQ(r.read(10, 1, {2, 1}, 1e-3, text), GcsError::kNone);
  EXPECT_EQ(parse(text).rows.size(), 1u);
  ASSERT_EQ(r.read(11, 0, {1}, 1e-3, text), GcsError::kNone);
  EXPECT_EQ(parse(text).header.at("NDATA"), "0");
}

// The largest answer there can be (every table on, the recorder full, every value as long as
// "{:.9g}" writes one) stays within the bound the header states and docs/gcs.md gives.
TEST(DataRecorderTest, FullestAnswerIsWithinTheStatedBound) {
  DataRecorder r;
  const int options[DataRecorder::kTables] = {1, 2, 3, 90, 1, 2, 7, 17};
  const char* sources[DataRecorder::kTables] = {"Z", "U", "V", "Z", "V", "V", "3", "2"};
  for (int t = 0; t < DataRecorder::kTables; ++t)
    ASSERT_EQ(r.configure(t + 1, sources[t], options[t]), GcsError::kNone) << t;
  RecorderInput in;
  for (std::size_t i = 0; i < 3; ++i) {
    in.target[i] = -1.23456789e-300;
    in.position[i] = 1.23456789e-300;  // the error, target - position, is -2.46913578e-300
    in.interferometer[i] = -1.23456789e-300;
    in.channel_V[i] = -1.23456789e-300;
    in.sensor_um[i] = -1.23456789e-300;
  }
  for (std::size_t k = 0; k < DataRecorder::kPoints + 5; ++k)
    r.record(in);
  ASSERT_EQ(r.points(), DataRecorder::kPoints);
  std::string text;
  ASSERT_EQ(r.read(1, -1, {}, 1e-3, text), GcsError::kNone);
  const Parsed p = parse(text);
  EXPECT_TRUE(p.framing_ok);
  ASSERT_EQ(p.rows.size(), DataRecorder::kPoints);
  EXPECT_EQ(p.rows.back().size(), static_cast<std::size_t>(DataRecorder::kTables));
  EXPECT_LE(text.size(), DataRecorder::kMaxAnswerBytes);
  EXPECT_GT(text.size(), DataRecorder::kMaxAnswerBytes * 9 / 10);  // the bound is not loose
  EXPECT_LT(DataRecorder::kMaxAnswerBytes, 1'200'000u);
}

TEST(DataRecorderTest, OffTableIsSkippedByDefaultRead) {
  DataRecorder r;
  ASSERT_EQ(r.configure(1, "Z", 0), GcsError::kNone);
  for (int k = 0; k < 2; ++k)
    r.record(input_at(k));
  std::string text;
  ASSERT_EQ(r.read(1, -1, {}, 1e-3, text), GcsError::kNone);
  const Parsed p = parse(text);
  EXPECT_EQ(p.header.at("DIM"), "1");
  EXPECT_EQ(p.header.at("NAME0"), "Current position of axis Z (um)");
  ASSERT_EQ(p.rows.size(), 2u);
  EXPECT_NEAR(p.rows[1].at(0), input_at(1).position[0], 1e-8);
}

// A DRR? made a part at a time (the server answers other clients between the parts)
// is read()'s answer byte for byte, each part whole rows of at most max_values values.
TEST(DataRecorderTest, PartsJoinedAreTheWholeRead) {
  DataRecorder r;
  ASSERT_EQ(r.configure(3, "1", 7), GcsError::kNone);
  for (int k = 0; k < 1000; ++k)
    r.record(input_at(k));
  std::string whole;
  ASSERT_EQ(r.read(3, 990, {}, 1e-3, whole), GcsError::kNone);
  std::string joined;
  DataRecorder::Reading reading;
  ASSERT_EQ(r.start_read(3, 990, {}, 1e-3, joined, reading), GcsError::kNone);
  int parts = 0;
  while (reading.pending()) {
    std::string part;
    DataRecorder::continue_read(reading, part, 100);  // 33 rows of 3 columns
    EXPECT_EQ(std::count(part.begin(), part.end(), '\n'), parts < 30 ? 33 : 0) << parts;
    joined += part;
    ++parts;
  }
  EXPECT_EQ(parts, 30);  // 990 rows
  EXPECT_EQ(joined, whole);
  EXPECT_EQ(whole.back(), '\n');
}

}  // namespace
}  // namespace piezoshift::host
