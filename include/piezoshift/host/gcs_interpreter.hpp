#pragma once
// The GCS 2.0 command interpreter of `piezoshift serve` (docs/gcs.md has the command table): it
// turns command lines into HostCommands for the real-time loop and answers queries from the
// loop's HostSamples. It runs on the server's one network thread (LineHandler), never on the loop.
// One table of commands (name, syntax, help, handler) serves the dispatch and HLP?; the handlers
// are defined by command group (system, motion, parameters, data recorder, wave generators) in
// src/host/gcs_*.cpp. The wave generators (WaveGenerators) and the recorder's trigger
// (RecordTrigger) are classes of their own.
//
//   per client   the last error, as PI defines ERR?: a failed command sets its GCS error
//                number (a later error replaces an earlier one); a failed set command answers
//                nothing, a failed query (name ending in '?') one empty line, so that no client
//                waits for an answer that never comes; ERR? answers the error and resets it to
//                0. A client that connects while a fault is latched starts with -1024
//   levels       CCL 1 advanced lets SPA write the P and I terms (servo_parameters.hpp)
//   immediate    the single-character commands #5 (moving, hex mask), #7 (ready, 0xB1), #8
//                (macro running, 0), #9 (wave generators running, hex mask), #24 (stop all)
//                arrive as the control byte alone (LineHandler::on_immediate)
//   servo        one semi-closed loop drives all three axes, so SVO switches Z, U and V together
//                (SVO with different values per axis is refused, 17); servo on starts from the
//                position the gauges show (MOV? := POS?), servo off holds the volts applied
//   motion       MOV and MVR set a whole pose, checked against StageModel::reachable (7);
//                with the servo off they are refused (5); SVA with the servo on too (79)
//   on target    ONT? of an axis is 1 when the servo is on, the loop has applied the last move
//                and |POS? - MOV?| <= tolerance has held for settle_time_s
//   overflow     OVF? of an axis is 1 when, in closed loop, a PID has sat at its output limit
//                while the axis was off target for settle_time_s (overflow_monitor.hpp)
//   faults       when the safety supervisor latches a fault, the servo is reported off and every
//                client's error becomes -1024; SVO (either value) clears the fault
//   STP, #24     stop the wave generators and hold where the stage is (servo on: MOV? :=
//                POS?; off: the volts applied); set error 10 for the client that sent it
//   wave gen.    generator g (1..3) plays the table WSL gives it into axis g (Z, U, V) in
//                closed loop (wave_generators.hpp); while it runs, MOV?, recorder option 1 and
//                ONT? follow the wave
//   recorder     a motion command (and WGO, WGR) restarts the recording from the first sample
//                whose tick applied it (record_trigger.hpp)
// Sample drops (the host thread stalled for > 4 s) are counted, never blocking the loop.
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "piezoshift/host/data_recorder.hpp"
#include "piezoshift/host/gcs_error.hpp"
#include "piezoshift/host/line_server.hpp"
#include "piezoshift/host/overflow_monitor.hpp"
#include "piezoshift/host/record_trigger.hpp"
#include "piezoshift/host/sample_observer.hpp"
#include "piezoshift/host/servo_parameters.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/host/wave_generators.hpp"
#include "piezoshift/runtime/host_link.hpp"

namespace piezoshift::host {

//! `(c)2026 piezoshift, E-727 compatible semi-closed-loop PZT phase shifter (DAQ), 0, 0.1.0`,
//! without the brackets when daq is empty.
std::string default_identification(const std::string& daq);

struct GcsOptions {
  double on_target_tolerance_um = 0.01;   //!< Z: 10 nm, ~7 sigma of the gauges' 1.5 nm noise
  double on_target_tolerance_urad = 0.5;  //!< U, V: 0.5 urad tilts P1..P3 by ~20 nm
  double settle_time_s = 0.01;            //!< within tolerance this long
  //! *IDN?: "E-727" lets clients that pick their handling by model (EPICS's motorPIGCS2
  //! matches the text) drive this server as an E-727; the rest says what it is.
  std::string identification = default_identification("");
};

struct GcsStats {
  std::uint64_t samples = 0;         //!< HostSamples taken from the loop
  std::uint64_t samples_missed = 0;  //!< ticks whose sample the ring dropped
  std::uint64_t commands_sent = 0;   //!< HostCommands pushed to the loop
  std::uint64_t lines = 0;           //!< command lines handled
  std::uint64_t errors = 0;          //!< GCS errors set
  std::uint64_t faults = 0;          //!< supervisor faults seen
  std::uint64_t answer_bytes = 0;    //!< answers made to command lines (parts included)
};

class GcsInterpreter final : public LineHandler {
 public:
  //! Axes, channels, tables or parameters one query names at most (`POS? Z Z ...`; more: error
  //! 24): an answer grows with its list, so the list is bounded, not only the line.
  static constexpr std::size_t kMaxQueryItems = 64;
  //! Every answer to one line, its parts joined, is at most this (the largest DRR?); a part
  //! (what one turn makes) at most kMaxPartBytes or, for the answers that echo an argument
  //! (SPA? items), the line's length and kMaxPartBytes.
  static constexpr std::size_t kMaxAnswerBytes = DataRecorder::kMaxAnswerBytes;
  static constexpr std::size_t kMaxPartBytes =
      DataRecorder::kHeaderBytes + DataRecorder::kValuesPerPart * DataRecorder::kValueBytes;

  GcsInterpreter(const StageModel& model, runtime::HostLink& link, double servo_cycle_s,
                 const GcsOptions& options);

  void on_connect(ClientId client) override;
  void on_disconnect(ClientId client) override;
  std::string on_line(ClientId client, std::string_view line) override;
  std::string on_overlong_line(ClientId client) override;
  bool is_immediate(char byte) const override;
  std::string on_immediate(ClientId client, char byte) override;
  void on_poll() override { drain(); }
  //! A DRR? answer is made a part at a time (DataRecorder::kValuesPerPart values): on_line()
  //! answers the header and the first part, more_answer() the next; a new line drops the rest.
  bool answer_pending(ClientId client) const override;
  std::string more_answer(ClientId client) override;

  //! Takes every sample the loop has pushed (also done before each command).
  void drain();
  const GcsStats& stats() const noexcept { return stats_; }
  const StageModel& model() const noexcept { return model_; }
  //! Also hands every sample to observer (null: none) after the recorder.
  void set_sample_observer(SampleObserver* observer) noexcept { observer_ = observer; }

  //! The names of every command the interpreter knows, as HLP? lists them: the command lines'
  //! (`MOV`, `POS?`, ...) and the single-character commands' (`#5`, ..., `#24`).
  static std::vector<std::string_view> command_names();

 private:
  using Args = std::vector<std::string_view>;
  struct Session {
    GcsError error = GcsError::kNone;  //!< the last error, until ERR? reads it
    int command_level = 0;             //!< CCL
    DataRecorder::Reading reading;     //!< the rest of a DRR? answer
  };
  //! Returns the answer (empty for set commands) or fails the session.
  using Handler = std::string (GcsInterpreter::*)(Session&, const Args&);
  //! A command line. An empty syntax takes no arguments (24 otherwise, before the handler).
  struct Command {
    std::string_view name;
    std::string_view syntax;  //!< the arguments, as HLP? shows them
    std::string_view help;    //!< one line
    Handler handler;
  };
  //! A single-character command: the control byte alone (#5 is the byte 5).
  struct Immediate {
    char byte;
    std::string_view name;
    std::string_view help;
    Handler handler;
  };
  static const Command kCommands[];
  static const Immediate kImmediates[];

  // Dispatch, HLP? (the table itself), sessions and the loop's samples (gcs_interpreter.cpp).
  std::string execute(Session& session, std::string_view name, const Args& args);
  void fail(Session& session, GcsError error);
  //! True for kNone; otherwise sets the error and returns false.
  bool accepted(Session& session, GcsError error);
  //! answer, or nothing with the error set.
  std::string reply(Session& session, GcsError error, std::string& answer);
  //! Pushes the command to the loop; false (and error 52 set) when the ring is full.
  bool send(Session& session, runtime::HostCommand command);
  void take(const runtime::HostSample& sample);
  std::string help(Session& s, const Args& args);

  // The controller and the session (gcs_system.cpp).
  std::string identification(Session& s, const Args& args);
  std::string syntax_version(Session& s, const Args& args);
  std::string axis_identifiers(Session& s, const Args& args);
  std::string stage_types(Session& s, const Args& args);
  std::string units(Session& s, const Args& args);
  std::string error_number(Session& s, const Args& args);
  std::string command_level(Session& s, const Args& args);
  std::string command_level_query(Session& s, const Args& args);
  std::string ready_query(Session& s, const Args& args);
  std::string macro_query(Session& s, const Args& args);

  // Motion: servo, moves, stop, open loop and where the stage is (gcs_motion.cpp).
  std::string servo(Session& s, const Args& args);
  std::string servo_query(Session& s, const Args& args);
  std::string move_absolute(Session& s, const Args& args) { return move(s, args, false); }
  std::string move_relative(Session& s, const Args& args) { return move(s, args, true); }
  std::string move(Session& s, const Args& args, bool relative);
  bool nominal_tilts(AxisValues& target, const std::array<bool, 3>& named) const;
  std::string target_query(Session& s, const Args& args);
  std::string position_query(Session& s, const Args& args);
  std::string on_target_query(Session& s, const Args& args);
  std::string overflow_query(Session& s, const Args& args);
  std::string stop(Session& s, const Args& args);
  std::string moving_query(Session& s, const Args& args);
  std::string velocity(Session& s, const Args& args);
  std::string velocity_query(Session& s, const Args& args);
  std::string velocity_control_query(Session& s, const Args& args);
  std::string open_loop(Session& s, const Args& args);
  std::string open_loop_query(Session& s, const Args& args);
  std::string voltage_query(Session& s, const Args& args);
  std::string lower_limit_query(Session& s, const Args& args);
  std::string upper_limit_query(Session& s, const Args& args);
  void moved();
  //! The targets in force: MOV's, with each running generator's axis at its wave value.
  AxisValues commanded() const;
  //! Bit a: axis a not on target or its generator running, or its command not applied yet.
  unsigned moving_mask() const;
  //! Open-loop values := the volts the loop applies now (servo off, STP).
  void hold_applied_volts();

  // Servo parameters (gcs_parameters.cpp).
  std::string parameters(Session& s, const Args& args);
  std::string set_parameters(Session& s, const Args& args);
  std::string parameter_list(Session& s, const Args& args);

  // The data recorder (gcs_data_recorder.cpp).
  std::string recorder_config(Session& s, const Args& args);
  std::string recorder_config_query(Session& s, const Args& args);
  std::string recorder_trigger(Session& s, const Args& args);
  std::string recorder_trigger_query(Session& s, const Args& args);
  std::string recorder_rate(Session& s, const Args& args);
  std::string recorder_rate_query(Session& s, const Args& args);
  std::string recorder_options(Session& s, const Args& args);
  std::string recorder_tables(Session& s, const Args& args);
  std::string recorder_length(Session& s, const Args& args);
  std::string recorder_read(Session& s, const Args& args);

  // The wave generators (gcs_wave_generator.cpp).
  std::string wave_define(Session& s, const Args& args);
  std::string wave_query(Session& s, const Args& args);
  std::string wave_select(Session& s, const Args& args);
  std::string wave_select_query(Session& s, const Args& args);
  std::string wave_cycles(Session& s, const Args& args);
  std::string wave_cycles_query(Session& s, const Args& args);
  std::string wave_rate(Session& s, const Args& args);
  std::string wave_rate_query(Session& s, const Args& args);
  std::string wave_start(Session& s, const Args& args);
  std::string wave_start_query(Session& s, const Args& args);
  std::string wave_running_query(Session& s, const Args& args);
  std::string wave_record_restart(Session& s, const Args& args);
  std::string wave_generators(Session& s, const Args& args);
  //! Starts generator g (WGO g 1); false with the error set.
  bool start_wave(Session& s, std::size_t g, long long mode);
  //! Stops every generator (STP, #24); false (52 set) when the ring is full.
  bool stop_waves(Session& s);
  //! Stops generator g (it holds where it is); false (52 set) when the ring is full.
  bool stop_wave(Session& s, std::size_t g);
  //! Waits (at most ~50 ms, draining samples) until the loop has applied generator g's last
  //! start or stop, so that the slot it no longer reads may be written.
  bool slot_free(std::size_t g);

  const StageModel& model_;
  runtime::HostLink& link_;
  double servo_cycle_s_;
  GcsOptions options_;
  std::uint64_t settle_samples_;
  std::unordered_map<ClientId, Session> sessions_;
  DataRecorder recorder_;
  RecordTrigger trigger_{recorder_};
  SampleObserver* observer_ = nullptr;
  ServoParameters servo_params_;
  // SPA's set until the loop acknowledges it; reverted if the loop refuses it.
  std::uint64_t configure_sequence_ = 0;
  control::SemiClosedLoopParams before_configure_{};
  GcsStats stats_;

  // The loop as last seen.
  bool have_sample_ = false;
  runtime::HostSample last_{};
  bool faulted_ = false;
  AxisValues position_{};

  // What the host has asked for.
  std::uint64_t sequence_ = 0;
  std::uint64_t move_sequence_ = 0;   // the last command that set the target or servo state
  std::uint64_t clear_sequence_ = 0;  // the last SVO (which clears a latched fault)
  bool servo_on_ = false;
  AxisValues target_{};
  // Axes whose target is the pose the gauges measured (servo-on, STP), not one a client set.
  std::array<bool, 3> measured_target_{};
  AxisValues open_loop_V_{};
  std::array<std::uint64_t, 3> settled_{};
  OverflowMonitor overflow_{settle_samples_};  // OVF?: pinned at a limit, off target
  std::array<double, 3> velocity_{};           // VEL, stored (velocity control is off, VCO? 0)
  WaveGenerators waves_{model_};               // one per axis
};

}  // namespace piezoshift::host
