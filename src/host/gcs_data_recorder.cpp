// The GCS data recorder commands: DRC, DRT, RTR, their queries, HDR?, TNR?, DRL? and DRR?.
#include "piezoshift/host/gcs_interpreter.hpp"

#include <algorithm>

#include <fmt/core.h>

#include "gcs_arguments.hpp"

namespace piezoshift::host {

using namespace gcs;

std::string GcsInterpreter::recorder_config(Session& s, const Args& args) {
  if (args.size() != 3) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  long long table = 0;
  long long option = 0;
  if (!parse_integer(args[0], table) || !parse_integer(args[2], option)) {
    fail(s, GcsError::kParamSyntax);
    return {};
  }
  if (table < 1 || table > DataRecorder::kTables) {
    fail(s, GcsError::kNoRecordTable);
    return {};
  }
  if (option < 0 || option > 1000) {
    fail(s, GcsError::kNoRecordOption);
    return {};
  }
  accepted(s, recorder_.configure(static_cast<int>(table), args[1], static_cast<int>(option)));
  return {};
}

std::string GcsInterpreter::recorder_config_query(Session& s, const Args& args) {
  std::string answer;
  const auto table = [this](int t) { return recorder_.describe_table(t); };
  return reply(s, id_lines(args, DataRecorder::kTables, GcsError::kNoRecordTable, table, answer),
               answer);
}

std::string GcsInterpreter::recorder_trigger(Session& s, const Args& args) {
  // "DRT {table} {source}" (PIPython with one trigger for all: table 0) or triples with a value.
  const std::size_t step = args.size() == 2 ? 2 : 3;
  if (args.empty() || args.size() % step != 0) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  int source = trigger_.source();
  for (std::size_t i = 0; i < args.size(); i += step) {
    long long table = 0;
    long long src = 0;
    if (!parse_integer(args[i], table) || !parse_integer(args[i + 1], src)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    if (table < 0 || table > DataRecorder::kTables) {
      fail(s, GcsError::kNoRecordTable);
      return {};
    }
    if (!RecordTrigger::is_source(src)) {
      fail(s, GcsError::kParamOutOfRange);
      return {};
    }
    source = static_cast<int>(src);  // one trigger serves all tables (they share one clock)
  }
  trigger_.set_source(source, sequence_);
  return {};
}

std::string GcsInterpreter::recorder_trigger_query(Session& s, const Args& args) {
  std::string answer;
  const auto trigger = [this](int) { return fmt::format("{} 0", trigger_.source()); };
  return reply(s, id_lines(args, DataRecorder::kTables, GcsError::kNoRecordTable, trigger, answer),
               answer);
}

std::string GcsInterpreter::recorder_rate(Session& s, const Args& args) {
  if (args.size() != 1) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  long long cycles = 0;
  if (!parse_integer(args[0], cycles)) {
    fail(s, GcsError::kParamSyntax);
    return {};
  }
  accepted(s, recorder_.set_rate(cycles));
  return {};
}

std::string GcsInterpreter::recorder_rate_query(Session&, const Args&) {
  return fmt::format("{}\n", recorder_.rate());
}

std::string GcsInterpreter::recorder_options(Session&, const Args&) {
  return framed(
      {"#RecordOptions", "0=Nothing is recorded", "1=Commanded position of axis",
       "2=Actual position of axis", "3=Position error of axis", "7=Piezo voltage of output channel",
       "17=Sensor (strain gauge) of input channel, um of actuator stroke",
       "90=Interferometer position of axis (piezoshift; NaN on hardware)", "#TriggerOptions",
       "0=Default setting: any command changing the position",
       "1=Any command changing the position (MOV, MVR, SVA, SVO, STP, WGO)",
       "2=Next command, then the default again", "4=Immediately", "#Parameters to be set with SPA",
       "none: the recorder is set with DRC, DRT, RTR", "#Additional information",
       fmt::format("{} datarecorder tables", DataRecorder::kTables),
       fmt::format("{} datapoints per table", DataRecorder::kPoints), "end of help"});
}

std::string GcsInterpreter::recorder_tables(Session&, const Args&) {
  return fmt::format("{}\n", DataRecorder::kTables);
}

std::string GcsInterpreter::recorder_length(Session& s, const Args& args) {
  std::string answer;
  const auto points = [this](int t) {
    return recorder_.describe_table(t) != "0 0" ? recorder_.points() : 0;
  };
  return reply(s, id_lines(args, DataRecorder::kTables, GcsError::kNoRecordTable, points, answer),
               answer);
}

std::string GcsInterpreter::recorder_read(Session& s, const Args& args) {
  long long start = 1;
  long long count = -1;
  std::vector<int> tables;
  for (std::size_t i = 0; i < args.size(); ++i) {
    long long v = 0;
    if (!parse_integer(args[i], v)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    if (i == 0) {
      start = v;
    } else if (i == 1) {
      if (v < 0) {
        fail(s, GcsError::kParamOutOfRange);
        return {};
      }
      count = v;
    } else if (tables.size() <= static_cast<std::size_t>(DataRecorder::kTables)) {
      // More than kTables names hold a repeat or a table that does not exist, which the first
      // kTables + 1 already show: a longer list costs no memory (every name is still parsed).
      tables.push_back(static_cast<int>(std::clamp<long long>(v, -1, 1000)));
    }
  }
  std::string answer;
  if (const GcsError e =
          recorder_.start_read(start, count, tables, servo_cycle_s_, answer, s.reading);
      e != GcsError::kNone) {
    fail(s, e);
    return {};
  }
  DataRecorder::continue_read(s.reading, answer, DataRecorder::kValuesPerPart);
  return answer;
}

}  // namespace piezoshift::host
