// piezoshift.Stage: a stage behind the real-time loop (procedures::LoopStation), as a GCS client
// drives `piezoshift serve`: servo, move, wait on target, position, the data recorder and the
// supervisor's faults as exceptions; a context manager whose exit ramps the outputs to 0 V.
// The loop runs on its own thread (real time on the twin's `sim-rt` or a Comedi board); every
// call that waits for it releases the GIL, and one mutex lets one Python thread in at a time.
// Poses are numpy arrays [Z um, tip urad, tilt urad] (serve's axes Z, U, V and units).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "bindings.hpp"
#include "piezoshift/procedures/loop_station.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace pr = ps::procedures;

using Calibration = std::variant<std::monostate, std::string, ps::control::SemiClosedLoopParams>;

Array pose_array(const ps::host::AxisValues& p) {
  return to_numpy(Vec3{p[0], p[1], p[2]});
}

class Stage {
 public:
  explicit Stage(const pr::LoopStationOptions& options) {
    py::gil_scoped_release release;
    station_ = std::make_unique<pr::LoopStation>(options);
  }

  // Runs f on the station with the GIL released and the station to itself.
  template <typename F>
  auto locked(F f) {
    py::gil_scoped_release release;
    const std::lock_guard<std::mutex> lock(mutex_);
    return f(*station_);
  }

  void move(std::optional<double> z_um, std::optional<double> tip_urad,
            std::optional<double> tilt_urad) {
    locked([&](pr::LoopStation& s) {
      ps::host::AxisValues pose = s.target();  // an axis not named keeps its target
      const std::optional<double> given[3] = {z_um, tip_urad, tilt_urad};
      for (std::size_t a = 0; a < 3; ++a)
        if (given[a])
          pose[a] = *given[a];
      s.move(pose);
    });
  }

  py::dict read_recording(double timeout_s) {
    pr::Recording r = locked([&](pr::LoopStation& s) { return s.read_recording(timeout_s); });
    py::dict d;
    d["time_s"] = to_numpy(r.time_s);
    for (const pr::RecorderSignal signal : r.signals) {
      const auto& rows = r.of(signal);
      d[pr::to_string(signal)] = to_numpy(std::vector<Vec3>(rows.begin(), rows.end()));
    }
    d["every"] = r.every;
    d["ticks_missed"] = r.ticks_missed;
    return d;
  }

  py::object fault() {
    const std::optional<pr::StationFault> f = locked([](pr::LoopStation& s) { return s.fault(); });
    if (!f)
      return py::none();
    py::dict d;
    d["name"] = f->name;
    d["channel"] = f->channel >= 1 ? py::object(py::int_(f->channel)) : py::object(py::none());
    d["tick"] = f->tick;
    d["time_s"] = f->t_s;
    d["description"] = f->description();
    return d;
  }

  pr::LoopStation& station() { return *station_; }

 private:
  std::mutex mutex_;
  std::unique_ptr<pr::LoopStation> station_;
};

pr::LoopStationOptions station_options(const std::string& daq, double rate_Hz, std::uint64_t seed,
                                       const Calibration& calibration,
                                       const std::optional<std::string>& config,
                                       const std::vector<std::string>& faults, bool free_run,
                                       double on_target_um, double on_target_urad, double settle_s,
                                       std::optional<std::int64_t> max_overruns, bool realtime) {
  pr::LoopStationOptions o;
  o.daq = daq;
  o.rate_Hz = rate_Hz;
  o.seed = seed;
  if (const auto* path = std::get_if<std::string>(&calibration))
    o.calibration_path = *path;
  if (const auto* params = std::get_if<ps::control::SemiClosedLoopParams>(&calibration)) {
    ps::calibration::LoopCalibration c;
    c.params = *params;
    c.source = "the calibration given";
    o.calibration = c;
  }
  o.config_path = config.value_or("");
  o.faults = faults;
  o.free_run = free_run;
  o.on_target_um = on_target_um;
  o.on_target_urad = on_target_urad;
  o.settle_s = settle_s;
  o.max_overruns = max_overruns;
  o.request_realtime = realtime;
  return o;
}

void bind_stage_errors(py::module_& m) {
  static py::exception<pr::StationFaulted> stage_fault(m, "StageFault", PyExc_RuntimeError);
  static py::exception<pr::StationTimeout> stage_timeout(m, "StageTimeout", PyExc_TimeoutError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p)
        std::rethrow_exception(p);
    } catch (const pr::StationFaulted& e) {
      // The exception carries the fault: e.name ("sgs-rail"), e.channel (1..3 or None).
      py::object error = py::handle(stage_fault.ptr())(e.what());
      error.attr("name") = e.fault().name;
      error.attr("channel") =
          e.fault().channel >= 1 ? py::object(py::int_(e.fault().channel)) : py::none();
      error.attr("time_s") = e.fault().t_s;
      PyErr_SetObject(stage_fault.ptr(), error.ptr());
    } catch (const pr::StationTimeout& e) {
      stage_timeout(e.what());
    }
  });
}

// The loop's life and its motion: the constructor, `with`, servo, move, wait on target.
void bind_stage_motion(py::class_<Stage>& stage) {
  const pr::LoopStationOptions defaults;
  stage
      .def(py::init([](const std::string& daq, double rate_Hz, std::uint64_t seed,
                       const Calibration& calibration, const std::optional<std::string>& config,
                       const std::vector<std::string>& faults, bool free_run, double on_target_um,
                       double on_target_urad, double settle_s,
                       std::optional<std::int64_t> max_overruns, bool realtime) {
             return std::make_unique<Stage>(
                 station_options(daq, rate_Hz, seed, calibration, config, faults, free_run,
                                 on_target_um, on_target_urad, settle_s, max_overruns, realtime));
           }),
           py::arg("daq") = "sim-rt", py::arg("rate_Hz") = defaults.rate_Hz,
           py::arg("seed") = defaults.seed, py::arg("calibration") = py::none(),
           py::arg("config") = py::none(), py::arg("faults") = std::vector<std::string>{},
           py::arg("free_run") = false, py::arg("on_target_um") = defaults.on_target_um,
           py::arg("on_target_urad") = defaults.on_target_urad,
           py::arg("settle_s") = defaults.settle_s, py::arg("max_overruns") = py::none(),
           py::arg("realtime") = false,
           "Builds the loop as `piezoshift serve` does and starts it, servo off at 0 V. "
           "calibration: a file, a SemiClosedLoopParams, or None (the twin's start-up "
           "calibration); faults: `--fault` specs, KIND@T_S[:CHANNEL] (the twin only); "
           "free_run: the twin's loop runs only while the stage waits (deterministic); "
           "realtime: ask SCHED_FIFO, pinning and mlockall for the loop's thread")
      .def("__enter__", [](Stage& s) -> Stage& { return s; })
      .def("__exit__",
           [](Stage& s, const py::object&, const py::object&, const py::object&) {
             s.locked([](pr::LoopStation& st) { st.close(); });
             return false;
           })
      .def(
          "servo", [](Stage& s, bool on) { s.locked([on](pr::LoopStation& st) { st.servo(on); }); },
          py::arg("on"),
          "SVO: on closes the loop at the pose the gauges show, off holds the volts applied; "
          "either clears a latched fault (StageFault when it latches again at once)")
      .def_property_readonly(
          "servo_on", [](Stage& s) { return s.locked([](auto& st) { return st.servo_on(); }); })
      .def("move", &Stage::move, py::arg("z_um") = py::none(), py::arg("tip_urad") = py::none(),
           py::arg("tilt_urad") = py::none(),
           "MOV: the pose (an axis not given keeps its target); InputError when out of reach, "
           "StageFault while a fault is latched")
      .def(
          "wait_on_target",
          [](Stage& s, double timeout_s) {
            s.locked([timeout_s](pr::LoopStation& st) { st.wait_on_target(timeout_s); });
          },
          py::arg("timeout_s") = 10.0,
          "Returns once every axis is within the on-target band for settle_s (ONT?); "
          "StageTimeout after timeout_s of loop time, StageFault when a fault latches");
}

// What the stage reads back (on target, poses, volts, the recorder, the fault, the limits), and
// close.
void bind_stage_readings(py::class_<Stage>& stage) {
  stage
      .def_property_readonly("on_target",
                             [](Stage& s) {
                               return s.locked([](pr::LoopStation& st) {
                                 st.update();
                                 return st.on_target();
                               });
                             })
      .def(
          "position",
          [](Stage& s) {
            return pose_array(s.locked([](pr::LoopStation& st) {
              st.update();
              return st.position();
            }));
          },
          "POS?: [Z um, tip urad, tilt urad] the strain gauges say")
      .def(
          "target",
          [](Stage& s) { return pose_array(s.locked([](auto& st) { return st.target(); })); },
          "MOV?: [Z um, tip urad, tilt urad]")
      .def(
          "interferometer",
          [](Stage& s) {
            return pose_array(s.locked([](pr::LoopStation& st) {
              st.update();
              return st.interferometer();
            }));
          },
          "The twin's interferometer as [Z um, tip urad, tilt urad]; NaN on hardware")
      .def(
          "output_V",
          [](Stage& s) {
            return to_numpy(s.locked([](pr::LoopStation& st) {
              if (!st.closed())
                st.update();
              return st.output_V();
            }));
          },
          "The DAQ's three output volts at the last tick (0 once closed)")
      .def(
          "record",
          [](Stage& s, std::size_t samples, std::uint64_t every,
             const std::vector<std::string>& signals) {
            std::vector<pr::RecorderSignal> parsed;
            for (const std::string& name : signals)
              parsed.push_back(pr::parse_recorder_signal(name));
            s.locked([&](pr::LoopStation& st) { st.record(samples, every, parsed); });
          },
          py::arg("samples"), py::arg("every") = 1, py::arg("signals") = std::vector<std::string>{},
          "Records `samples` points, one every `every` ticks, from the next tick: signals "
          "among target, position, interferometer, output_V, sensor_um (empty: all)")
      .def("read_recording", &Stage::read_recording, py::arg("timeout_s") = 10.0,
           "Waits for the recording and returns a dict: time_s (n,), one (n, 3) array per "
           "signal, every, ticks_missed")
      .def_property_readonly("fault", &Stage::fault,
                             "None, or the latched fault: name, channel, tick, time_s, "
                             "description")
      .def(
          "close", [](Stage& s) { s.locked([](pr::LoopStation& st) { st.close(); }); },
          "Ramps the outputs to 0 V and stops the loop (idempotent; also at the `with` exit)")
      .def_property_readonly(
          "closed", [](Stage& s) { return s.locked([](auto& st) { return st.closed(); }); })
      .def_property_readonly("daq", [](Stage& s) { return s.station().daq_name(); })
      .def_property_readonly("rate_Hz", [](Stage& s) { return s.station().rate_Hz(); })
      .def_property_readonly("calibration_source",
                             [](Stage& s) { return s.station().calibration_source(); })
      .def_property_readonly(
          "min_limits", [](Stage& s) { return pose_array(s.station().model().min_limits()); },
          "TMN?: [Z um, tip urad, tilt urad]")
      .def_property_readonly(
          "max_limits", [](Stage& s) { return pose_array(s.station().model().max_limits()); },
          "TMX?: [Z um, tip urad, tilt urad]");
}

}  // namespace

void bind_station(py::module_& m) {
  bind_stage_errors(m);
  py::class_<Stage> stage(
      m, "Stage",
      "A stage behind the real-time loop (docs/python.md): the twin at the loop's "
      "rate (daq='sim-rt') or a Comedi board ('comedi:/dev/comediN'); use it in a "
      "`with` block, whose exit ramps the outputs to 0 V");
  bind_stage_motion(stage);
  bind_stage_readings(stage);
}

}  // namespace piezoshift::python
