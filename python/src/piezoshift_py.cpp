// Python bindings of piezoshift's offline API (docs/python.md): design, configuration, the digital
// twin, the bench, the paper's experiments, calibration, the fits, the metrics and reproduce().
// Value structs become Python classes with the same field names (nested structs are returned by
// reference, so cfg.design.hinge.thickness_m = ... edits in place). Three-channel values (Vec3)
// and 3x3 matrices come back as numpy copies and are set by assigning a whole value; time series
// (std::vector<double>) come back as 1-D numpy arrays; images (frames, maps) as 2-D arrays. The
// real-time loop is reached through Stage (station_py.cpp), and measure() runs it on the twin's
// simulated clock.
// Each library module's bindings are in a file of its own (bindings.hpp); this one only calls
// them, in an order that registers every type before a signature names it.
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_piezoshift, m) {
  namespace bind = piezoshift::python;
  m.doc() =
      "piezoshift: design, digital twin, calibration, experiments and the real-time loop (Stage)";
  bind::bind_errors(m);
  bind::bind_psi(m);
  bind::bind_control(m);
  bind::bind_design(m);
  bind::bind_twin_params(m);
  bind::bind_config(m);
  bind::bind_twin(m);
  bind::bind_experiments(m);
  bind::bind_calibration(m);
  bind::bind_reproduction(m);
  bind::bind_camera(m);
  bind::bind_instrument(m);
  bind::bind_tolerance(m);
  bind::bind_station(m);
}
