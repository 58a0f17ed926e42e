#include "piezoshift/host/data_recorder.hpp"

#include <algorithm>
#include <iterator>

#include <fmt/format.h>

namespace piezoshift::host {

namespace {

constexpr int kTarget = 1;
constexpr int kPosition = 2;
constexpr int kError = 3;
constexpr int kOutputVoltage = 7;
constexpr int kSensor = 17;
constexpr int kInterferometer = 90;

bool is_axis_option(int option) {
  return option == kTarget || option == kPosition || option == kError || option == kInterferometer;
}
bool is_channel_option(int option) {
  return option == kOutputVoltage || option == kSensor;
}

int axis_index(std::string_view s) {
  for (Axis a : kAxes)
    if (s == axis_name(a))
      return static_cast<int>(a);
  return -1;
}

}  // namespace

DataRecorder::DataRecorder() {
  rows_.reserve(kPoints);
  // As a PI controller ships: table 1 the target, table 2 the position of the first axis.
  tables_[0] = Table{kTarget, 0};
  tables_[1] = Table{kPosition, 0};
}

GcsError DataRecorder::configure(int table, std::string_view source, int option) {
  if (!table_exists(table))
    return GcsError::kNoRecordTable;
  Table t{option, 0};
  if (option == 0) {
    t.source = 0;
  } else if (is_axis_option(option)) {
    t.source = axis_index(source);
    if (t.source < 0)
      return GcsError::kInvalidAxis;
  } else if (is_channel_option(option)) {
    if (source != "1" && source != "2" && source != "3")
      return GcsError::kParamOutOfRange;
    t.source = source[0] - '1';
  } else {
    return GcsError::kNoRecordOption;
  }
  tables_[static_cast<std::size_t>(table - 1)] = t;
  restart();
  return GcsError::kNone;
}

std::string DataRecorder::describe_table(int table) const {
  const Table& t = tables_[static_cast<std::size_t>(table - 1)];
  if (t.option == 0)
    return "0 0";
  if (is_axis_option(t.option))
    return fmt::format("{} {}", axis_name(kAxes[static_cast<std::size_t>(t.source)]), t.option);
  return fmt::format("{} {}", t.source + 1, t.option);
}

GcsError DataRecorder::set_rate(long long cycles) {
  if (cycles < 1 || cycles > kMaxRate)
    return GcsError::kParamOutOfRange;
  rate_ = static_cast<int>(cycles);
  restart();
  return GcsError::kNone;
}

void DataRecorder::restart() noexcept {
  rows_.clear();
  cycle_ = 0;
}

double DataRecorder::value(const Table& t, const RecorderInput& in) const {
  const auto i = static_cast<std::size_t>(t.source);
  switch (t.option) {
    case kTarget:
      return in.target[i];
    case kPosition:
      return in.position[i];
    case kError:
      return in.target[i] - in.position[i];
    case kInterferometer:
      return in.interferometer[i];
    case kOutputVoltage:
      return in.channel_V[i];
    case kSensor:
      return in.sensor_um[i];
    default:
      return 0.0;
  }
}

void DataRecorder::record(const RecorderInput& in) {
  const bool on_rate = cycle_ % static_cast<std::uint64_t>(rate_) == 0;
  ++cycle_;
  if (!on_rate || rows_.size() >= kPoints)
    return;
  std::array<double, kTables> row{};
  for (std::size_t t = 0; t < tables_.size(); ++t)
    row[t] = tables_[t].option == 0 ? 0.0 : value(tables_[t], in);
  rows_.push_back(row);
}

std::string DataRecorder::name(const Table& t) const {
  const auto i = static_cast<std::size_t>(t.source);
  const auto of_axis = [i](const char* signal) {
    return fmt::format("{} of axis {} ({})", signal, axis_name(kAxes[i]), axis_unit(kAxes[i]));
  };
  switch (t.option) {
    case kTarget:
      return of_axis("Target position");
    case kPosition:
      return of_axis("Current position");
    case kError:
      return of_axis("Position error");
    case kInterferometer:
      return of_axis("Interferometer position");
    case kOutputVoltage:
      return fmt::format("Voltage of output channel {} (V)", i + 1);
    case kSensor:
      return fmt::format("Sensor of input channel {} (um)", i + 1);
    default:
      return "Nothing";
  }
}

GcsError DataRecorder::choose(const std::vector<int>& tables, std::vector<int>& chosen) const {
  chosen.clear();
  if (tables.empty()) {
    for (int t = 1; t <= kTables; ++t)
      if (tables_[static_cast<std::size_t>(t - 1)].option != 0)
        chosen.push_back(t);
    return chosen.empty() ? GcsError::kTableDeactivated : GcsError::kNone;
  }
  // Each table at most once (as a repeated axis or wave generator is refused), so an answer has
  // at most kTables columns however long the list.
  std::array<bool, kTables> named{};
  for (int t : tables) {
    if (!table_exists(t))
      return GcsError::kNoRecordTable;
    const auto i = static_cast<std::size_t>(t - 1);
    if (tables_[i].option == 0)
      return GcsError::kTableDeactivated;
    if (named[i])
      return GcsError::kParamSyntax;
    named[i] = true;
    chosen.push_back(t);
  }
  return GcsError::kNone;
}

GcsError DataRecorder::read(long long start, long long count, const std::vector<int>& tables,
                            double servo_cycle_s, std::string& answer) const {
  Reading reading;
  const GcsError e = start_read(start, count, tables, servo_cycle_s, answer, reading);
  while (reading.pending())
    continue_read(reading, answer, kValuesPerPart);
  return e;
}

GcsError DataRecorder::start_read(long long start, long long count, const std::vector<int>& tables,
                                  double servo_cycle_s, std::string& answer,
                                  Reading& reading) const {
  answer.clear();
  reading = Reading{};
  std::vector<int> chosen;
  if (const GcsError e = choose(tables, chosen); e != GcsError::kNone)
    return e;
  if (start < 1)
    return GcsError::kParamOutOfRange;
  // Compared as what is left after start, never as start + count: any long long is safe.
  const auto held = static_cast<long long>(rows_.size());
  if (start > held + 1 || (count >= 0 && count > held - (start - 1)))
    return GcsError::kNotEnoughData;
  const long long n = count < 0 ? held - (start - 1) : count;
  // n <= kPoints and chosen.size() <= kTables here, so the answer is at most kMaxAnswerBytes;
  // checked before one byte of it is made.
  const auto rows = static_cast<std::size_t>(n);
  if (rows > kPoints || chosen.size() > static_cast<std::size_t>(kTables))
    return GcsError::kParamOutOfRange;

  std::vector<std::string> header;
  header.push_back("# REM piezoshift data recorder");
  header.push_back("# VERSION = 1");
  header.push_back("# TYPE = 1");
  header.push_back("# SEPARATOR = 32");
  header.push_back(fmt::format("# DIM = {}", chosen.size()));
  header.push_back(fmt::format("# SAMPLE_TIME = {:.9g}", servo_cycle_s * rate_));
  header.push_back(fmt::format("# NDATA = {}", n));
  for (std::size_t c = 0; c < chosen.size(); ++c)
    header.push_back(
        fmt::format("# NAME{} = {}", c, name(tables_[static_cast<std::size_t>(chosen[c] - 1)])));
  header.push_back("# END_HEADER");
  for (std::size_t l = 0; l < header.size(); ++l)
    answer += header[l] + (l + 1 < header.size() || rows > 0 ? " \n" : "\n");
  reading.columns = chosen.size();
  reading.values.reserve(rows * chosen.size());
  const auto first = static_cast<std::size_t>(start - 1);
  for (std::size_t r = first; r < first + rows; ++r)
    for (const int t : chosen)
      reading.values.push_back(rows_[r][static_cast<std::size_t>(t - 1)]);
  return GcsError::kNone;
}

void DataRecorder::continue_read(Reading& reading, std::string& answer, std::size_t max_values) {
  if (!reading.pending() || reading.columns == 0)
    return;
  const std::size_t rows = std::max<std::size_t>(1, max_values / reading.columns);
  const std::size_t end = std::min(reading.values.size(), reading.next + rows * reading.columns);
  answer.reserve(answer.size() + (end - reading.next) * kValueBytes);
  for (std::size_t i = reading.next; i < end; i += reading.columns) {
    for (std::size_t c = 0; c < reading.columns; ++c) {
      if (c > 0)
        answer += ' ';
      fmt::format_to(std::back_inserter(answer), "{:.9g}", reading.values[i + c]);
    }
    answer += i + reading.columns < reading.values.size() ? " \n" : "\n";
  }
  reading.next = end;
  if (!reading.pending())
    reading = Reading{};  // the memory back
}

}  // namespace piezoshift::host
