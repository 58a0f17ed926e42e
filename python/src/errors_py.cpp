// Bindings of the errors bad input raises, with the C++ message: core::InputError becomes
// piezoshift.InputError, a ValueError so that `except ValueError` catches bad input too;
// calibration::FitError and experiments::MetricsError become FitError and MetricsError, both
// InputErrors. rig::ProcedureFailed (a procedure or measurement that is not valid: the CLI's exit
// status 4) becomes ProcedureFailed, a RuntimeError. std::invalid_argument is pybind11's own
// ValueError.
#include <pybind11/pybind11.h>

#include <exception>

#include "bindings.hpp"
#include "piezoshift/calibration/fit_error.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/experiments/metrics_error.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::python {

void bind_errors(py::module_& m) {
  namespace ps = piezoshift;
  static py::exception<ps::core::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<ps::calibration::FitError> fit_error(m, "FitError", input_error.ptr());
  static py::exception<ps::experiments::MetricsError> metrics_error(m, "MetricsError",
                                                                    input_error.ptr());
  static py::exception<ps::rig::ProcedureFailed> procedure_failed(m, "ProcedureFailed",
                                                                  PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p)
        std::rethrow_exception(p);
    } catch (const ps::calibration::FitError& e) {
      fit_error(e.what());
    } catch (const ps::experiments::MetricsError& e) {
      metrics_error(e.what());
    } catch (const ps::core::InputError& e) {
      input_error(e.what());
    } catch (const ps::rig::ProcedureFailed& e) {
      procedure_failed(e.what());
    }
  });
}

}  // namespace piezoshift::python
