// Bindings of the design module (docs/design.md): the flexure's inputs, the design report of
// Eqs. 1 to 4 and the hinge search, with the C++ field names.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "piezoshift/design/design_evaluation.hpp"
#include "piezoshift/design/design_inputs.hpp"
#include "piezoshift/design/flexure.hpp"
#include "piezoshift/design/hinge_search.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace d = ps::design;

void bind_inputs(py::module_& m) {
  py::class_<d::ActuatorParams>(m, "ActuatorParams")
      .def(py::init<>())
      .PS_RW(d::ActuatorParams, stiffness_N_per_um)
      .PS_RW(d::ActuatorParams, nominal_stroke_um)
      .PS_RW(d::ActuatorParams, pushing_force_N)
      .PS_RW(d::ActuatorParams, pulling_force_N)
      .PS_RW(d::ActuatorParams, capacitance_F)
      .PS_RW(d::ActuatorParams, resonance_frequency_Hz)
      .PS_RW(d::ActuatorParams, length_m);
  py::class_<d::MaterialParams>(m, "MaterialParams")
      .def(py::init<>())
      .PS_RW(d::MaterialParams, elastic_modulus_Pa)
      .PS_RW(d::MaterialParams, poisson_ratio)
      .PS_RW(d::MaterialParams, density_kg_per_m3)
      .PS_RW(d::MaterialParams, allowable_stress_Pa);
  py::class_<d::HingeParams>(m, "HingeParams")
      .def(py::init<>())
      .PS_RW(d::HingeParams, width_m)
      .PS_RW(d::HingeParams, thickness_m)
      .PS_RW(d::HingeParams, radius_m)
      .PS_RW(d::HingeParams, link_length_m);
  py::class_<d::MechanismParams>(m, "MechanismParams")
      .def(py::init<>())
      .PS_RW(d::MechanismParams, moving_mass_kg);
  py::class_<d::DesignInputs>(m, "DesignInputs")
      .def(py::init<>())
      .PS_RW(d::DesignInputs, actuator)
      .PS_RW(d::DesignInputs, material)
      .PS_RW(d::DesignInputs, hinge)
      .PS_RW(d::DesignInputs, mechanism)
      .def(
          "problem", [](const d::DesignInputs& in) { return d::design_inputs_problem(in); },
          "Why the inputs are not physical, or '' when they are");
}

void bind_evaluation(py::module_& m) {
  using Ev = d::DesignEvaluation;
  py::class_<Ev>(m, "DesignEvaluation")
      .PS_RO(Ev, hinge_angular_stiffness_Nm_per_rad)
      .PS_RO(Ev, mechanism_stiffness_N_per_um)
      .PS_RO(Ev, stiffness_rule_limit_N_per_um)
      .PS_RO(Ev, stiffness_ratio)
      .PS_RO(Ev, rule_ka_over_10_ok)
      .PS_RO(Ev, available_displacement_um)
      .PS_RO(Ev, stroke_loss_percent)
      .PS_RO(Ev, spring_force_at_stroke_N)
      .PS_RO(Ev, force_within_pushing_limit)
      .PS_RO(Ev, hinge_rotation_at_stroke_rad)
      .PS_RO(Ev, hinge_moment_at_stroke_Nm)
      .PS_RO(Ev, stress_concentration_factor)
      .PS_RO(Ev, nominal_stress_at_stroke_Pa)
      .PS_RO(Ev, max_stress_at_stroke_Pa)
      .PS_RO(Ev, allowable_stress_Pa)
      .PS_RO(Ev, stress_margin)
      .PS_RO(Ev, stress_ok)
      .PS_RO(Ev, natural_frequency_Hz)
      .PS_RO(Ev, thickness_to_radius);

  m.def("evaluate_design", &d::evaluate_design, py::arg("inputs"),
        "The design report of Eqs. 1 to 4, stress and natural frequency (ValueError when the "
        "inputs are not physical)");
  m.def("hinge_angular_stiffness_Nm_per_rad", &d::hinge_angular_stiffness_Nm_per_rad,
        py::arg("material"), py::arg("hinge"), "Eq. 2");
  m.def("mechanism_stiffness_N_per_um", &d::mechanism_stiffness_N_per_um, py::arg("material"),
        py::arg("hinge"), "Eq. 3");
  m.def("available_displacement_um", &d::available_displacement_um, py::arg("actuator"),
        py::arg("mechanism_stiffness_N_per_um"), "Eq. 1");
}

void bind_hinge_search(py::module_& m) {
  py::class_<d::SearchRange>(m, "SearchRange", "Grid values min, min + step, ... up to max [m]")
      .def(py::init<>())
      .def(py::init([](double min_m, double max_m, double step_m) {
             return d::SearchRange{min_m, max_m, step_m};
           }),
           py::arg("min_m"), py::arg("max_m"), py::arg("step_m"))
      .PS_RW(d::SearchRange, min_m)
      .PS_RW(d::SearchRange, max_m)
      .PS_RW(d::SearchRange, step_m);
  py::class_<d::HingeSearchSpace>(m, "HingeSearchSpace",
                                  "The grid over t, R, b and L; the default holds Table 3")
      .def(py::init<>())
      .PS_RW(d::HingeSearchSpace, thickness)
      .PS_RW(d::HingeSearchSpace, radius)
      .PS_RW(d::HingeSearchSpace, width)
      .PS_RW(d::HingeSearchSpace, link_length);
  py::class_<d::SearchConstraints>(m, "SearchConstraints")
      .def(py::init<>())
      .PS_RW(d::SearchConstraints, max_stiffness_ratio)
      .PS_RW(d::SearchConstraints, min_stress_margin)
      .PS_RW(d::SearchConstraints, max_thickness_to_radius)
      .PS_RW(d::SearchConstraints, min_natural_frequency_Hz);
  py::enum_<d::SearchRanking>(m, "SearchRanking")
      .value("NATURAL_FREQUENCY", d::SearchRanking::natural_frequency)
      .value("STRESS_MARGIN", d::SearchRanking::stress_margin);
  py::class_<d::HingeCandidate>(m, "HingeCandidate")
      .PS_RO(d::HingeCandidate, hinge)
      .PS_RO(d::HingeCandidate, evaluation);
  py::class_<d::HingeSearchResult>(m, "HingeSearchResult")
      .PS_RO(d::HingeSearchResult, evaluated_count)
      .PS_RO(d::HingeSearchResult, geometry_rejected_count)
      .PS_RO(d::HingeSearchResult, feasible_count)
      .PS_RO(d::HingeSearchResult, candidates);
  m.def(
      "search_hinge_designs",
      [](const d::DesignInputs& base, const d::HingeSearchSpace& space,
         const d::SearchConstraints& constraints, std::size_t max_candidates,
         d::SearchRanking ranking) {
        py::gil_scoped_release nogil;
        return d::search_hinge_designs(base, space, constraints, max_candidates, ranking);
      },
      py::arg("base"), py::arg_v("space", d::HingeSearchSpace{}, "HingeSearchSpace()"),
      py::arg_v("constraints", d::SearchConstraints{}, "SearchConstraints()"),
      py::arg("max_candidates") = 10,
      py::arg_v("ranking", d::SearchRanking::natural_frequency, "SearchRanking.NATURAL_FREQUENCY"),
      "Grid search over the hinge dimensions (`piezoshift design --search`), best first");
}

}  // namespace

void bind_design(py::module_& m) {
  bind_inputs(m);
  bind_evaluation(m);
  bind_hinge_search(m);
}

}  // namespace piezoshift::python
