#pragma once
// The GCS 2.0 command interpreter of `piezoshift serve` (docs/gcs.md has the command table): it
// turns command lines into HostCommands for the real-time loop and answers queries from the
// loop's HostSamples. It runs on the server's one network thread (LineHandler), never on the loop.
//
//   per client   an error queue: a failed command queues its GCS error number; a failed set
//                command answers nothing, a failed query (name ending in '?') one empty line,
//                so that no client waits for an answer that never comes; ERR? pops the oldest,
//                0 when empty
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
//   faults       when the safety supervisor latches a fault, the servo is reported off and every
//                client's queue gets -1024; SVO (either value) clears the fault
//   STP, #24     stop the wave generators and hold where the stage is (servo on: MOV? :=
//                POS?; off: the volts applied); queue error 10 for the client that sent it
//   wave gen.    generator g (1..3) plays the table WSL gives it (WaveTables) into axis g
//                (Z, U, V) in closed loop: WGO copies the table into a slot of fixed storage
//                and hands the slot to the loop (runtime/wave_generator.hpp has the lifetime
//                rule); while it runs, MOV?, recorder option 1 and ONT? follow the wave
//   recorder     a motion command (and WGO, WGR) restarts the recording from the first sample
//                whose tick applied it (HostSample::applied_sequence), so a recording is
//                aligned to the tick the command took effect
// Sample drops (the host thread stalled for > 4 s) are counted, never blocking the loop.
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "piezoshift/host/data_recorder.hpp"
#include "piezoshift/host/gcs_error.hpp"
#include "piezoshift/host/line_server.hpp"
#include "piezoshift/host/sample_observer.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/host/wave_tables.hpp"
#include "piezoshift/runtime/host_link.hpp"

namespace piezoshift::host {

struct GcsOptions {
  double on_target_tolerance_um = 0.01;   //!< Z: 10 nm, ~7 sigma of the gauges' 1.5 nm noise
  double on_target_tolerance_urad = 0.5;  //!< U, V: 0.5 urad tilts P1..P3 by ~20 nm
  double settle_time_s = 0.01;            //!< within tolerance this long
  std::size_t error_queue_length = 16;    //!< per client; the oldest errors are kept when full
  std::string identification = "piezoshift, semi-closed-loop PZT phase shifter, 0, 0.1.0";
};

struct GcsStats {
  std::uint64_t samples = 0;         //!< HostSamples taken from the loop
  std::uint64_t samples_missed = 0;  //!< ticks whose sample the ring dropped
  std::uint64_t commands_sent = 0;   //!< HostCommands pushed to the loop
  std::uint64_t lines = 0;           //!< command lines handled
  std::uint64_t errors = 0;          //!< GCS errors queued
  std::uint64_t faults = 0;          //!< supervisor faults seen
};

class GcsInterpreter final : public LineHandler {
 public:
  GcsInterpreter(const StageModel& model, runtime::HostLink& link, double servo_cycle_s,
                const GcsOptions& options);

  void on_connect(ClientId client) override;
  void on_disconnect(ClientId client) override;
  std::string on_line(ClientId client, std::string_view line) override;
  std::string on_overlong_line(ClientId client) override;
  bool is_immediate(char byte) const override;
  std::string on_immediate(ClientId client, char byte) override;
  void on_poll() override { drain(); }

  //! Takes every sample the loop has pushed (also done before each command).
  void drain();
  const GcsStats& stats() const noexcept { return stats_; }
  const StageModel& model() const noexcept { return model_; }
  //! Also hands every sample to observer (null: none) after the recorder.
  void set_sample_observer(SampleObserver* observer) noexcept { observer_ = observer; }

 private:
  using Args = std::vector<std::string_view>;
  struct Session {
    std::deque<GcsError> errors;
  };

  std::string execute(Session& session, std::string_view name, const Args& args);
  void fail(Session& session, GcsError error);
  //! True for kNone; otherwise queues the error and returns false.
  bool accepted(Session& session, GcsError error);
  //! Open-loop values := the volts the loop applies now (servo off, STP).
  void hold_applied_volts();
  //! answer, or nothing with the error queued.
  std::string reply(Session& session, GcsError error, std::string& answer);
  //! Pushes the command to the loop; false (and error 52 queued) when the ring is full.
  bool send(Session& session, runtime::HostCommand command);
  void take(const runtime::HostSample& sample);
  void moved();
  //! The targets in force: MOV's, with each running generator's axis at its wave value.
  AxisValues commanded() const;
  //! Bit a: axis a not on target or its generator running, or its command not applied yet.
  unsigned moving_mask() const;
  unsigned wave_mask() const;
  //! Stops every generator (STP, #24); false (52 queued) when the ring is full.
  bool stop_waves(Session& s);
  //! Stops generator g (it holds where it is); false (52 queued) when the ring is full.
  bool stop_wave(Session& s, std::size_t g);

  // Commands; each returns the answer (empty for set commands) or fails the session.
  std::string move(Session& s, const Args& args, bool relative);
  std::string servo(Session& s, const Args& args);
  std::string open_loop(Session& s, const Args& args);
  std::string stop(Session& s, const Args& args);
  std::string recorder_config(Session& s, const Args& args);
  std::string recorder_rate(Session& s, const Args& args);
  std::string recorder_read(Session& s, const Args& args);
  std::string recorder_trigger(Session& s, const Args& args);
  std::string parameters(Session& s, const Args& args);
  std::string velocity(Session& s, const Args& args);
  std::string wave_define(Session& s, const Args& args);
  std::string wave_query(Session& s, const Args& args);
  std::string wave_start(Session& s, const Args& args);
  //! WSL, WGC, WTR: "{generator} {value} ..." pairs (WTR: {generator} {rate} {interpolation}).
  std::string wave_setting(Session& s, std::string_view name, const Args& args);
  //! WSL?, WGC?, WGO?, WTR?: "{generator}=..." lines.
  std::string wave_setting_query(Session& s, std::string_view name, const Args& args);
  std::string wave_record_restart(Session& s, const Args& args);

  const StageModel& model_;
  runtime::HostLink& link_;
  double servo_cycle_s_;
  GcsOptions options_;
  std::uint64_t settle_samples_;
  std::unordered_map<ClientId, Session> sessions_;
  DataRecorder recorder_;
  SampleObserver* observer_ = nullptr;
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
  AxisValues open_loop_V_{};
  std::array<std::uint64_t, 3> settled_{};
  std::uint64_t record_from_sequence_ = 0;  // record samples whose tick applied this command
  int trigger_ = 0;                         // DRT source (0 and 1: motion commands)
  std::array<double, 3> velocity_{};        // VEL, stored (velocity control is off, VCO? 0)

  // Wave generators, one per axis. The slots are fixed storage the loop reads (two per
  // generator: the one playing and the one the next WGO fills); allocated once, here.
  static constexpr std::size_t kGenerators = 3;
  using Slot = std::array<double, WaveTables::kPoints>;
  WaveTables waves_;
  std::unique_ptr<std::array<Slot, 2 * kGenerators>> slots_;
  std::array<int, kGenerators> wave_table_{1, 2, 3};        // WSL
  std::array<long long, kGenerators> wave_cycles_{};        // WGC, 0: until stopped
  std::array<long long, kGenerators> wave_rate_{1, 1, 1};   // WTR
  std::array<long long, kGenerators> wave_mode_{};          // WGO, as last set
  std::array<int, kGenerators> wave_slot_{-1, -1, -1};      // the slot last handed over
  std::array<std::uint64_t, kGenerators> wave_sequence_{};  // the last start/stop sent
  std::array<bool, kGenerators> wave_running_{};            // as the loop last said
  std::array<double, kGenerators> wave_min_{};              // range of the table playing
  std::array<double, kGenerators> wave_max_{};
  //! Waits (at most ~50 ms, draining samples) until the loop has applied generator g's last
  //! start or stop, so that the slot it no longer reads may be written.
  bool slot_free(std::size_t g);
  //! Restarts the recording for a motion command when the trigger (DRT) says so.
  void motion_trigger();
};

}  // namespace piezoshift::host
