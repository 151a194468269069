// System identification (`vibid arx | pem | tfest | compare`) through the workflow library: the
// request in, the command's JSON and text out.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "vibid/workflow/sysid_run.hpp"

namespace vibid::python {
namespace {

py::tuple Report(const workflow::SysidReport& r) {
  return py::make_tuple(ToPython(r.json), r.text);
}

}  // namespace

void RegisterSysid(py::module_& m) {
  using R = workflow::SysidRecord;
  py::class_<R>(m, "_SysidRecord")
      .def(py::init<>())
      .def_readwrite("path", &R::path)
      .def_readwrite("input", &R::input)
      .def_readwrite("output", &R::output)
      .def_readwrite("fs_hz", &R::fs_hz)
      .def_readwrite("detrend", &R::detrend)
      .def_readwrite("decimate", &R::decimate);
  using P = workflow::PolyRequest;
  py::class_<P>(m, "_PolyRequest")
      .def(py::init<>())
      .def_readwrite("record", &P::record)
      .def_readwrite("estimate_range", &P::estimate_range)
      .def_readwrite("validate_range", &P::validate_range)
      .def_readwrite("d2c", &P::d2c);
  m.def(
      "arx",
      [](const P& poly, int na, int nb, int nk, const std::string& select, int max_order) {
        workflow::ArxRequest r{poly, na, nb, nk, select, max_order};
        workflow::SysidReport out;
        {
          py::gil_scoped_release release;
          out = workflow::RunArx(r);
        }
        return Report(out);
      },
      py::arg("poly"), py::arg("na"), py::arg("nb"), py::arg("nk"), py::arg("select"),
      py::arg("max_order"));
  m.def(
      "pem",
      [](const P& poly, const std::string& structure, const std::string& orders,
         int max_iterations) {
        workflow::PemRequest r{poly, structure, orders, max_iterations};
        workflow::SysidReport out;
        {
          py::gil_scoped_release release;
          out = workflow::RunPem(r);
        }
        return Report(out);
      },
      py::arg("poly"), py::arg("structure"), py::arg("orders"), py::arg("max_iterations"));
  m.def(
      "tfest",
      [](const R& record, int np, int nz, const std::string& ic, const std::string& estimate_range,
         const std::string& validate_range, int max_iterations) {
        workflow::TfestRequest r{record,        np, nz, ic, estimate_range, validate_range,
                                 max_iterations};
        workflow::SysidReport out;
        {
          py::gil_scoped_release release;
          out = workflow::RunTfest(r);
        }
        return Report(out);
      },
      py::arg("record"), py::arg("np"), py::arg("nz"), py::arg("ic"), py::arg("estimate_range"),
      py::arg("validate_range"), py::arg("max_iterations"));
  m.def(
      "compare",
      [](const R& record, const std::string& model, const std::string& horizon,
         const std::string& method, int substeps, const std::string& ic, const std::string& range,
         int input_dof, int output_dof) {
        workflow::CompareRequest r{record, model, horizon,   method,    substeps,
                                   ic,     range, input_dof, output_dof};
        workflow::CompareReport out;
        {
          py::gil_scoped_release release;
          out = workflow::RunCompare(r);
        }
        return py::make_tuple(ToPython(out.json), out.text, out.t_s, out.y, out.y_model);
      },
      py::arg("record"), py::arg("model"), py::arg("horizon"), py::arg("method"),
      py::arg("substeps"), py::arg("ic"), py::arg("range"), py::arg("input_dof"),
      py::arg("output_dof"));
}

}  // namespace vibid::python
