// Bindings of the controller's parameters (include/piezoshift/control/): what the offline API
// takes and calibration returns, the paper's controller and the improved one, with the same
// field names as the C++ structs and as the calibration file.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "piezoshift/control/parameter_check.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/core/input_error.hpp"
#include "values.hpp"

namespace py = pybind11;
namespace ps = piezoshift;
using piezoshift::python::to_numpy;
using ps::control::Mat3;
using ps::control::Vec3;

namespace {

using Hc = ps::control::HysteresisCreepParams;

// The first n values of a fixed-size C++ list (n beyond its size reads as all of it).
template <std::size_t N>
std::vector<double> head(const std::array<double, N>& a, std::size_t n) {
  return {a.begin(), a.begin() + static_cast<std::ptrdiff_t>(std::min(n, N))};
}

// Refuses a list the controller could not hold or would misread, naming the field and the value.
template <std::size_t N>
void check_list(const std::vector<double>& v, const char* name, bool (*ok)(double),
                const char* rule, bool increasing = false) {
  if (v.size() > N)
    throw ps::core::InputError(std::string(name) + ": at most " + std::to_string(N) +
                               " values, not " + std::to_string(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (ok(v[i]) && !(increasing && i > 0 && !(v[i] > v[i - 1])))
      continue;
    std::ostringstream what;
    what << name << "[" << i << "] = " << v[i] << ": " << rule;
    throw ps::core::InputError(what.str());
  }
}

template <std::size_t N>
void copy_list(std::array<double, N>& a, const std::vector<double>& v) {
  a = {};
  std::copy(v.begin(), v.end(), a.begin());
}

bool positive(double x) {
  return x > 0.0;
}
bool non_negative(double x) {
  return x >= 0.0;
}

void set_thresholds(Hc& p, const std::vector<double>& r) {
  check_list<ps::control::kMaxModelOperators>(r, "threshold_um", positive,
                                              "must be positive and increasing", true);
  copy_list(p.threshold_um, r);
}

void set_weights(Hc& p, const std::vector<double>& w) {
  check_list<ps::control::kMaxModelOperators>(w, "weight", non_negative,
                                              "must be >= 0 (the model's inverse needs it)");
  copy_list(p.weight, w);
}

// The thresholds and the weights share one count in C++ (operators): each list may be set alone
// only with as many values as there are operators, so the two cannot disagree.
void set_same_count(Hc& p, const std::vector<double>& v, const char* name,
                    void (*set)(Hc&, const std::vector<double>&)) {
  if (v.size() != p.operators)
    throw ps::core::InputError(std::string(name) + ": " + std::to_string(v.size()) +
                               " values for " + std::to_string(p.operators) +
                               " operators (set_operators(threshold_um, weight) changes how many)");
  set(p, v);
}

// One channel's hysteresis and creep model (control/hysteresis_creep_model.hpp), the improved
// controller's feedforward. Lists with a count in C++ are whole Python lists here.
void bind_model(py::module_& m) {
  namespace c = ps::control;
  py::class_<Hc>(m, "HysteresisCreepParams")
      .def(py::init<>())
      .PS_RW(Hc, offset_um)
      .PS_RW(Hc, linear_weight)
      .def_property(
          "threshold_um", [](const Hc& p) { return head(p.threshold_um, p.operators); },
          [](Hc& p, const std::vector<double>& r) {
            set_same_count(p, r, "threshold_um", set_thresholds);
          })
      .def_property(
          "weight", [](const Hc& p) { return head(p.weight, p.operators); },
          [](Hc& p, const std::vector<double>& w) { set_same_count(p, w, "weight", set_weights); })
      .def(
          "set_operators",
          [](Hc& p, const std::vector<double>& r, const std::vector<double>& w) {
            if (r.size() != w.size())
              throw ps::core::InputError("set_operators: " + std::to_string(w.size()) +
                                         " weights for " + std::to_string(r.size()) +
                                         " thresholds");
            Hc q = p;  // p unchanged when a list is refused
            set_thresholds(q, r);
            set_weights(q, w);
            q.operators = r.size();
            p = q;
          },
          py::arg("threshold_um"), py::arg("weight"),
          "Sets the play operators' thresholds r_j [um of command] and weights w_j, as many of "
          "each (at most 16)")
      .def_property(
          "creep_time_constant_s",
          [](const Hc& p) { return head(p.creep_time_constant_s, p.creep_terms); },
          [](Hc& p, const std::vector<double>& tau) {
            check_list<c::kMaxCreepTerms>(tau, "creep_time_constant_s", positive,
                                          "must be positive");
            copy_list(p.creep_time_constant_s, tau);
            p.creep_terms = tau.size();
          })
      .PS_RW(Hc, creep_gain);
}

// The improved controller's parts. The shaper's taps are a fixed-size array with a count in C++;
// here they are one whole list, set at once, so that the count and the values cannot disagree.
// The model is a list of three HysteresisCreepParams, the controller's own, as the scaling is.
void bind_improved(py::module_& m) {
  namespace c = ps::control;
  bind_model(m);
  py::enum_<c::ControllerKind>(m, "ControllerKind")
      .value("paper", c::ControllerKind::kPaper)
      .value("improved", c::ControllerKind::kImproved);

  py::class_<c::SignalScaling>(m, "SignalScaling")
      .def(py::init<>())
      .PS_RW(c::SignalScaling, sgs_um_per_V)
      .PS_RW(c::SignalScaling, sgs_offset_V)
      .PS_RW(c::SignalScaling, drive_V_per_um)
      .PS_RW(c::SignalScaling, drive_offset_V)
      .def("sgs_to_um", &c::SignalScaling::sgs_to_um)
      .def("um_to_dac", &c::SignalScaling::um_to_dac)
      .def("dac_to_um", &c::SignalScaling::dac_to_um);

  py::class_<c::ShaperParams>(m, "ShaperParams")
      .def(py::init<>())
      .def_property(
          "taps",
          [](const c::ShaperParams& s) {
            return std::vector<double>(s.weight.begin(), s.weight.begin() + s.taps);
          },
          [](c::ShaperParams& s, const std::vector<double>& w) {
            if (w.empty() || w.size() > c::kMaxShaperTaps)
              throw ps::core::InputError("taps: 1 to " + std::to_string(c::kMaxShaperTaps) +
                                         " weights");
            s.weight = {};
            std::copy(w.begin(), w.end(), s.weight.begin());
            s.taps = w.size();
          })
      .PS_RW(c::ShaperParams, rate_um_per_s);

  py::class_<c::ImprovedParams>(m, "ImprovedParams")
      .def(py::init<>())
      .PS_RW(c::ImprovedParams, sample_time_s)
      .PS_RW(c::ImprovedParams, model)
      .PS_RW(c::ImprovedParams, shaper)
      .PS_RW(c::ImprovedParams, correction_ki)
      .PS_RW(c::ImprovedParams, correction_ki_max)
      .PS_RW(c::ImprovedParams, correction_boost_error_um)
      .PS_RW(c::ImprovedParams, correction_limit_um)
      .PS_RW(c::ImprovedParams, reference_delay_ticks)
      .PS_RW(c::ImprovedParams, headroom_fraction)
      .PS_RW(c::ImprovedParams, command_slew_um_per_s)
      .PS_RW(c::ImprovedParams, slew_approach_um);
}

}  // namespace

namespace piezoshift::python {

void bind_control(py::module_& m) {
  py::class_<ps::control::PidGains>(m, "PidGains")
      .def(py::init<>())
      .def(py::init([](double kp, double ki, double kd) {
             return ps::control::PidGains{kp, ki, kd};
           }),
           py::arg("kp"), py::arg("ki"), py::arg("kd"))
      .PS_RW(ps::control::PidGains, kp)
      .PS_RW(ps::control::PidGains, ki)
      .PS_RW(ps::control::PidGains, kd);

  py::class_<ps::control::CubicPolynomial>(m, "CubicPolynomial")
      .def(py::init<>())
      .def(py::init([](double p3, double p2, double p1, double p0) {
             return ps::control::CubicPolynomial{p3, p2, p1, p0};
           }),
           py::arg("p3"), py::arg("p2"), py::arg("p1"), py::arg("p0"))
      .PS_RW(ps::control::CubicPolynomial, p3)
      .PS_RW(ps::control::CubicPolynomial, p2)
      .PS_RW(ps::control::CubicPolynomial, p1)
      .PS_RW(ps::control::CubicPolynomial, p0)
      .def("__call__", [](const ps::control::CubicPolynomial& p, double x) { return p(x); })
      .def("derivative", &ps::control::CubicPolynomial::derivative)
      .def_static("identity", &ps::control::CubicPolynomial::identity);

  py::class_<ps::control::TransmissionMatrix>(m, "TransmissionMatrix")
      .def(py::init<>())
      .def(py::init([](const Mat3& a) { return ps::control::TransmissionMatrix{a}; }), py::arg("a"))
      .PS_V3(ps::control::TransmissionMatrix, a)
      .def("__call__",
           [](const ps::control::TransmissionMatrix& t, const Vec3& z) { return to_numpy(t(z)); })
      .def_static("identity", &ps::control::TransmissionMatrix::identity);

  bind_improved(m);

  using Scl = ps::control::SemiClosedLoopParams;
  py::class_<Scl>(m, "SemiClosedLoopParams")
      .def(py::init<>())
      .PS_RW(Scl, kind)
      .PS_RW(Scl, scaling)
      .PS_RW(Scl, improved)
      .def(
          "problem",
          [](const Scl& p, double loop_sample_time_s) {
            return std::string(
                ps::control::to_string(ps::control::params_problem(p, loop_sample_time_s)));
          },
          py::arg("loop_sample_time_s"),
          "Why a loop at this sample time could not run these parameters; '' when it could "
          "(control/parameter_check.hpp)")
      .PS_RW(Scl, sample_time_s)
      .PS_RW(Scl, gains)
      .PS_RW(Scl, gains_sample_time_s)
      .PS_RW(Scl, output_min_um)
      .PS_RW(Scl, output_max_um)
      .PS_RW(Scl, deadband_um)
      .PS_RW(Scl, derivative_filter)
      .PS_RW(Scl, polynomial)
      .PS_RW(Scl, matrix);

  using Out = ps::control::ControllerOutput;
  py::class_<Out>(m, "ControllerOutput")
      .PS_V3(Out, dac_V)
      .PS_V3(Out, target_um)
      .PS_V3(Out, feedback_um)
      .PS_V3(Out, command_um)
      .PS_RO(Out, saturated_mask);
}

}  // namespace piezoshift::python
