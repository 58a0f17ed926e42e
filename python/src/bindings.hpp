#pragma once
// The binding functions, one file per library module (docs/python.md). PYBIND11_MODULE
// (piezoshift_py.cpp) calls them in an order that registers every type before a signature names
// it: pybind11 writes a docstring's types when the function is defined, so a later registration
// would leave the C++ name in it.
#include <pybind11/pybind11.h>

namespace piezoshift::python {

namespace py = pybind11;

void bind_errors(py::module_& m);        // errors_py.cpp: InputError, FitError, MetricsError,
                                         // ProcedureFailed
void bind_psi(py::module_& m);           // psi_py.cpp
void bind_control(py::module_& m);       // control_py.cpp
void bind_design(py::module_& m);        // design_py.cpp
void bind_twin_params(py::module_& m);   // plant_py.cpp: before ProjectConfig, which holds them
void bind_config(py::module_& m);        // config_py.cpp
void bind_twin(py::module_& m);          // plant_py.cpp: after ProjectConfig, which builds one
void bind_experiments(py::module_& m);   // experiments_py.cpp
void bind_calibration(py::module_& m);   // calibration_py.cpp
void bind_reproduction(py::module_& m);  // reproduction_py.cpp
void bind_camera(py::module_& m);        // camera_py.cpp
void bind_instrument(py::module_& m);    // instrument_py.cpp: after the controller and cameras
void bind_tolerance(py::module_& m);     // tolerance_py.cpp
void bind_station(py::module_& m);       // station_py.cpp: Stage, StageFault, StageTimeout

}  // namespace piezoshift::python
