// The extension module `vibid._vibid`; the package `vibid` (vibid/__init__.py) wraps its results
// in small classes.
#include <pybind11/pybind11.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "bindings.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/verdict.hpp"
#include "vibid/device/error.hpp"

namespace vibid::python {

py::object ToPython(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

namespace {

// The first number JSON cannot hold (NaN, +-inf) among dicts and lists, named from `path` on as
// the library names a model file's fields (list entries from 1); "" when every number is finite.
// json.dumps' own refusal names no field.
std::string NonFinite(const py::handle& object, const std::string& path) {
  if (py::isinstance<py::float_>(object)) {
    const double x = object.cast<double>();
    if (std::isfinite(x)) return "";
    return (path.empty() ? std::string("value") : path) + " = " +
           (std::isnan(x) ? "nan"
            : x > 0.0     ? "inf"
                          : "-inf");
  }
  if (py::isinstance<py::dict>(object)) {
    for (const auto& item : object.cast<py::dict>()) {
      const std::string key = py::str(item.first).cast<std::string>();
      const std::string found = NonFinite(
          item.second, path.empty() ? "field \"" + key + "\"" : path + "[\"" + key + "\"]");
      if (!found.empty()) return found;
    }
    return "";
  }
  if (py::isinstance<py::list>(object) || py::isinstance<py::tuple>(object)) {
    std::size_t i = 0;
    for (const auto& entry : object) {
      const std::string found = NonFinite(entry, path + "[" + std::to_string(++i) + "]");
      if (!found.empty()) return found;
    }
  }
  return "";
}

}  // namespace

nlohmann::json FromPython(const py::handle& object, const std::string& source) {
  const std::string non_finite = NonFinite(object, "");
  if (!non_finite.empty()) {
    throw InputError(source + ": " + non_finite + " must be a finite number");
  }
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
  m.attr("__version__") = VIBID_VERSION;  // the build's version, as `vibid --version` prints
  vibid::python::RegisterErrors(m);
  vibid::python::RegisterModel(m);
  vibid::python::RegisterBoard(m);
  vibid::python::RegisterAnalysis(m);
  vibid::python::RegisterObserver(m);
  vibid::python::RegisterSysid(m);
  vibid::python::RegisterWatch(m);
}
