// The disturbance observer: design and quantization for the board (`vibid dob design`), the
// board's fixed-point replay and the double-precision one (`vibid dob run`), the zero-phase
// low-pass of the estimate, and the agreement with a measured force (`vibid dob compare`).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/calibration_builder.hpp"
#include "vibid/device/calibration_upload.hpp"
#include "vibid/dob/compare.hpp"
#include "vibid/dob/design.hpp"
#include "vibid/dob/design_json.hpp"
#include "vibid/dob/lowpass.hpp"
#include "vibid/dob/model_plant.hpp"
#include "vibid/dob/quantize.hpp"
#include "vibid/model/model.hpp"
#include "vibid/workflow/observer_design.hpp"

namespace vibid::python {
namespace {

using Vector = Eigen::Ref<const Eigen::VectorXd>;

py::tuple Design(const model::Model& m, const workflow::ObserverDesignRequest& request) {
  dob::DobDesign design;
  {
    py::gil_scoped_release release;
    design = workflow::DesignObserverFor(m, request);
  }
  return py::make_tuple(ToPython(dob::DesignToJson(design)), design.max_pole_radius,
                        design.valid_band_lo_hz, design.valid_band_hi_hz,
                        design.fixed.predicted_noise_rms_n, design.fixed.predicted_snr_db);
}

/// Inputs as the observer file orders them: sensors first, the force last.
std::vector<Eigen::VectorXd> Inputs(const std::vector<Vector>& inputs) {
  std::vector<Eigen::VectorXd> out;
  for (const Vector& v : inputs) out.emplace_back(v);
  return out;
}

py::tuple RunFixed(const py::handle& design, const std::vector<Vector>& inputs) {
  const dob::ObserverFile f = dob::ObserverFromJson(FromPython(design, "design"), "design");
  std::vector<Eigen::VectorXd> in = Inputs(inputs);
  dob::FixedRun run;
  {
    py::gil_scoped_release release;
    run = dob::RunFixed(f.description, in);
  }
  py::array_t<std::int32_t> q31(static_cast<py::ssize_t>(run.d_hat_q31.size()));
  std::copy(run.d_hat_q31.begin(), run.d_hat_q31.end(), q31.mutable_data());
  return py::make_tuple(run.d_hat_n, q31, run.saturations);
}

Eigen::VectorXd RunFloat(const py::handle& design, const std::vector<Vector>& inputs) {
  const dob::ObserverFile f = dob::ObserverFromJson(FromPython(design, "design"), "design");
  std::vector<Eigen::VectorXd> in = Inputs(inputs);
  py::gil_scoped_release release;
  return dob::RunFloat(f.paths, in);
}

py::dict Compare(const Vector& estimate, const Vector& measured, double fs_hz, double max_delay_s) {
  dob::Agreement a;
  {
    py::gil_scoped_release release;
    a = dob::CompareSignals(estimate, measured, fs_hz, max_delay_s);
  }
  py::dict d;
  d["fit_percent"] = a.fit_percent;
  d["correlation"] = a.correlation;
  d["delay_s"] = a.delay_s;
  d["rmse_n"] = a.rmse_n;
  return d;
}

}  // namespace

void RegisterObserver(py::module_& m) {
  // The request `vibid dob design` fills from its options; its defaults are the CLI's.
  using O = workflow::ObserverDesignRequest;
  py::class_<O>(m, "_ObserverDesignRequest")
      .def(py::init<>())
      .def_readwrite("order", &O::order)
      .def_readwrite("relative_degree", &O::relative_degree)
      .def_readwrite("tau_s", &O::tau_s)
      .def_readwrite("fs_hz", &O::fs_hz)
      .def_readwrite("input_dof", &O::input_dof)
      .def_readwrite("output_dof", &O::output_dof)
      .def_readwrite("sensor", &O::sensor)
      .def_readwrite("form", &O::form)
      .def_readwrite("discretize", &O::discretize)
      .def_readwrite("prototype", &O::prototype)
      .def_readwrite("leak_hz", &O::leak_hz)
      .def_readwrite("force_fs_n", &O::force_fs_n)
      .def_readwrite("sensor_fs", &O::sensor_fs)
      .def_readwrite("output_fs_n", &O::output_fs_n);
  m.def("dob_design", &Design, py::arg("model"), py::arg("request"));
  // The observer's place and full scales a sensors file gives (`vibid dob design --sensors`).
  m.def(
      "take_sensor_full_scales",
      [](O& request, const py::handle& sensors, const std::string& source, bool force_given,
         bool sensor_given, bool input_dof_given, bool output_dof_given, bool sensor_kind_given) {
        const device::SensorSet set = device::SensorsFromJson(FromPython(sensors, source), source);
        const std::string placed =
            device::PlaceObserver(set, request.input_dof, input_dof_given, request.output_dof,
                                  output_dof_given, request.sensor, sensor_kind_given);
        const std::string took = device::TakeSensorFullScales(
            set, request.input_dof, request.output_dof, request.sensor, request.force_fs_n,
            force_given, request.sensor_fs, sensor_given);
        return placed + (placed.empty() || took.empty() ? "" : ", ") + took;
      },
      py::arg("request"), py::arg("sensors"), py::arg("source"), py::arg("force_given"),
      py::arg("sensor_given"), py::arg("input_dof_given"), py::arg("output_dof_given"),
      py::arg("sensor_kind_given"));
  m.def("dob_run_fixed", &RunFixed, py::arg("design"), py::arg("inputs"));
  m.def("dob_run_float", &RunFloat, py::arg("design"), py::arg("inputs"));
  m.def(
      "lowpass",
      [](const Vector& x, double cutoff_hz, double fs_hz, int order) {
        Require(cutoff_hz > 0.0 && cutoff_hz < fs_hz / 2.0,
                "--lowpass-hz must lie below fs/2 = " + std::to_string(fs_hz / 2.0) + " Hz");
        py::gil_scoped_release release;
        return Eigen::VectorXd(dob::FiltFilt(dob::ButterworthLowpass(order, cutoff_hz, fs_hz), x));
      },
      py::arg("x"), py::arg("cutoff_hz"), py::arg("fs_hz"), py::arg("order"));
  m.def("dob_compare", &Compare, py::arg("estimate"), py::arg("measured"), py::arg("fs_hz"),
        py::arg("max_delay_s"));
}

}  // namespace vibid::python
