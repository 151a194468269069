// The extension module `vibid._vibid`; the package `vibid` (vibid/__init__.py) wraps its results
// in small classes.
#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/verdict.hpp"
#include "vibid/device/error.hpp"

namespace vibid::python {

py::object ToPython(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

nlohmann::json FromPython(const py::handle& object) {
  const std::string text = py::module_::import("json")
                               .attr("dumps")(object, py::arg("allow_nan") = false)
                               .cast<std::string>();
  return nlohmann::json::parse(text);
}

void RegisterErrors(py::module_& m) {
  // Board errors are vibid.DeviceError; bad input is ValueError with the CLI's message; Ctrl-C
  // during a transfer is KeyboardInterrupt.
  static py::exception<device::DeviceError> device_error(m, "DeviceError", PyExc_RuntimeError);
  device_error.attr("__doc__") =
      "A board failed: none found, a transfer that timed out or broke off, a refused request, "
      "another protocol major. The message names what failed, as the CLI prints it.";
  static py::exception<NumericalError> numerical_error(m, "NumericalError", PyExc_ArithmeticError);
  numerical_error.attr("__doc__") =
      "A computation ran on valid input but produced no usable result (a solver's failure, an "
      "observer the design refuses); the message says why, as the CLI prints it.";
  static py::exception<FlaggedError> flagged_error(m, "FlaggedResultError", PyExc_ValueError);
  flagged_error.attr("__doc__") =
      "A result or model whose verdict is flagged (the library's own checks say not to use it): "
      "identify returns it, and dob_design, report and Board.cal_upload take it, only with "
      "accept_flagged=True. The message names the reasons. A ValueError.";
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const FlaggedError& e) {
      flagged_error(e.what());
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const NumericalError& e) {
      numerical_error(e.what());
    } catch (const device::Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    } catch (const device::DeviceError& e) {
      device_error(e.what());
    }
  });
}

}  // namespace vibid::python

PYBIND11_MODULE(_vibid, m) {
  m.doc() = "vibid: identification of mass-spring rigs and the board's disturbance observer";
  vibid::python::RegisterErrors(m);
  vibid::python::RegisterModel(m);
  vibid::python::RegisterBoard(m);
  vibid::python::RegisterAnalysis(m);
  vibid::python::RegisterObserver(m);
  vibid::python::RegisterSysid(m);
  vibid::python::RegisterWatch(m);
}
