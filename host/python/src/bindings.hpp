// Registration functions of the extension module `vibid._vibid`, one per area. The binding layer
// converts only: every decision is a library function the CLI calls too.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include <nlohmann/json_fwd.hpp>

namespace vibid::python {

namespace py = pybind11;

void RegisterErrors(py::module_& m);
void RegisterModel(py::module_& m);
void RegisterAnalysis(py::module_& m);
void RegisterBoard(py::module_& m);
void RegisterObserver(py::module_& m);
void RegisterSysid(py::module_& m);
void RegisterWatch(py::module_& m);

/// A JSON document as Python objects (dict, list, float...), through Python's json module: the
/// same objects `vibid ... --json` prints.
py::object ToPython(const nlohmann::json& j);
/// A Python dict (or list...) as JSON, through Python's json module. A NaN or infinity is refused
/// (InputError, so ValueError) naming its field as the library names a file's fields, from
/// `source` on (`model: field "masses"[2] = nan must be finite ...`, entries counted from 1).
nlohmann::json FromPython(const py::handle& object, const std::string& source);

}  // namespace vibid::python
