// Models (modal, FRF, simulation) and recordings: conversions between numpy arrays and the
// library's types. Arrays of float64 in C order come in without a copy.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <optional>
#include <utility>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/recording_facts.hpp"
#include "vibid/ident/sample_instants.hpp"
#include "vibid/model/force.hpp"
#include "vibid/model/frf.hpp"
#include "vibid/model/modal.hpp"
#include "vibid/model/model.hpp"
#include "vibid/common/verdict.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/model/simulate.hpp"

namespace vibid::python {
namespace {

py::dict ModalDict(const model::Model& m) {
  model::ModalResult r;
  {
    py::gil_scoped_release release;
    r = model::Modal(m);
  }
  py::dict d;
  d["omega_rad_s"] = r.omega_rad_s;
  d["freq_hz"] = r.freq_hz;
  d["zeta"] = r.zeta;
  d["shapes"] = r.shapes;
  d["ratio"] = r.ratio;
  d["damping"] = model::DampingKindName(r.damping);
  return d;
}

py::dict SimulateDict(const model::Model& m, const std::vector<std::string>& forces, double dt_s,
                      double t_end_s, const std::string& method, const Eigen::VectorXd& x0_m,
                      const Eigen::VectorXd& v0_m_s) {
  model::SimulationOptions options;
  options.method = model::ParseMethod(method);
  options.dt_s = dt_s;
  options.t_end_s = t_end_s;
  options.x0_m = x0_m;
  options.v0_m_s = v0_m_s;
  model::ForceInput force;
  for (const std::string& spec : forces) force.shapes.push_back(model::ParseForceShape(spec));
  model::SimulationResult r;
  {
    py::gil_scoped_release release;
    r = model::Simulate(m, force, options);
  }
  py::dict d;
  d["t_s"] = r.t_s;
  d["x_m"] = r.x_m;
  d["v_m_s"] = r.v_m_s;
  d["a_m_s2"] = r.a_m_s2;
  d["force_n"] = r.force_n;
  return d;
}

/// A recording as (names, data shaped (channels, samples), fs_hz, t0_s, sample instants
/// {column: us} from its sidecar, or from the opening line of a recording written before it,
/// the sidecar's facts as JSON text or None).
py::tuple ReadRecording(const std::string& path, std::optional<double> fs_hz,
                        const std::string& time_column, const std::vector<std::string>& channels) {
  RecordingOptions options;
  options.fs_hz = fs_hz;
  options.time_column = time_column;
  options.channels = channels;
  Recording r;
  std::optional<ident::SampleInstants> instants;
  std::optional<ident::RecordingFacts> facts;
  {
    py::gil_scoped_release release;
    r = LoadRecording(path, options);
    instants = ident::ReadSampleInstants(path);
    facts = ident::ReadRecordingFacts(path);
  }
  py::dict instants_us;
  if (instants) {
    for (const auto& [name, us] : instants->instants_us) instants_us[py::str(name)] = us;
  }
  const auto n = static_cast<py::ssize_t>(r.samples());
  const auto k = static_cast<py::ssize_t>(r.table.columns.size());
  py::array_t<double> data({k, n});
  double* out = data.mutable_data();
  for (py::ssize_t c = 0; c < k; ++c) {
    const Eigen::VectorXd& col = r.table.columns[static_cast<std::size_t>(c)];
    std::copy(col.data(), col.data() + n, out + c * n);
  }
  py::object facts_json = py::none();
  if (facts) facts_json = py::str(ident::FormatRecordingFacts(*facts));
  return py::make_tuple(r.table.names, data, r.fs_hz, r.t0_s, instants_us, facts_json);
}

/// Writes columns (rows of `data`) as a CSV vibid reads back bit-identical, and its sidecar with
/// the sampling instants {column: us} (none: a sidecar left at that path is removed).
void WriteCsv(const std::string& path, const std::vector<std::string>& names,
              const py::array_t<double, py::array::c_style>& data,
              const std::vector<std::pair<std::string, double>>& instants_us,
              const std::optional<std::string>& facts_json) {
  Require(data.ndim() == 2, "data must be 2-D (channels, samples)");
  Require(data.shape(1) > 0, "the recording is empty (no samples)");
  Require(static_cast<std::size_t>(data.shape(0)) == names.size(),
          "data has " + std::to_string(data.shape(0)) + " rows for " +
              std::to_string(names.size()) + " names");
  std::vector<Eigen::VectorXd> columns;
  for (py::ssize_t c = 0; c < data.shape(0); ++c)
    columns.emplace_back(Eigen::Map<const Eigen::VectorXd>(data.data(c, 0), data.shape(1)));
  const std::string text = FormatCsv(names, columns);
  py::gil_scoped_release release;
  // The sidecar first: a CSV is never left beside a sidecar of another. The recording's facts
  // when it has them (checked against its columns), else its instants alone.
  if (facts_json)
    ident::WriteRecordingFacts(path,
                               ident::ParseRecordingFacts(*facts_json, names, path + ".json"));
  else
    ident::WriteRecordingSidecar(path, names, instants_us);
  WriteFileAtomic(path, text);
}

}  // namespace

void RegisterModel(py::module_& m) {
  py::class_<model::Model>(m, "_Model")
      .def(py::init([](const Eigen::MatrixXd& m_kg, const Eigen::MatrixXd& k_n_per_m,
                       const std::optional<Eigen::MatrixXd>& c_ns_per_m) {
             model::Model mo{
                 m_kg,
                 c_ns_per_m ? *c_ns_per_m : Eigen::MatrixXd::Zero(m_kg.rows(), m_kg.cols()).eval(),
                 k_n_per_m};
             model::Validate(mo);
             return mo;
           }),
           py::arg("m_kg"), py::arg("k_n_per_m"), py::arg("c_ns_per_m") = py::none())
      .def_readonly("m_kg", &model::Model::m_kg)
      .def_readonly("c_ns_per_m", &model::Model::c_ns_per_m)
      .def_readonly("k_n_per_m", &model::Model::k_n_per_m)
      .def_property_readonly("dofs", &model::Model::dofs)
      .def("to_dict", [](const model::Model& mo) { return ToPython(model::ModelToJson(mo)); });
  m.def("load_model", &model::LoadModel, py::arg("path"));
  // A model file's verdict (none stated: {"level": "ok", "reasons": [], "stated": false}).
  m.def(
      "model_verdict",
      [](const py::handle& d, const std::string& source) {
        const Verdict v = model::ModelVerdict(FromPython(d, source), source);
        nlohmann::json j = VerdictToJson(v);
        j["stated"] = v.stated;
        return ToPython(j);
      },
      py::arg("d"), py::arg("source") = "model");
  // The check every step that takes a model to the board makes (common/verdict.hpp):
  // FlaggedResultError naming the reasons and `option` for a flagged one not accepted.
  m.def(
      "require_usable",
      [](const py::handle& verdict, bool accept, const std::string& what, const std::string& step,
         const std::string& option) {
        nlohmann::json j = FromPython(verdict, what + ": verdict");
        const bool stated = !j.contains("stated") || j["stated"].get<bool>();
        j.erase("stated");
        j.erase("text");
        Verdict v = VerdictFromJson(j, what + ": verdict");
        v.stated = stated;
        RequireUsable(v, accept, what, step, option);
      },
      py::arg("verdict"), py::arg("accept_flagged"), py::arg("what"), py::arg("step"),
      py::arg("option"));
  m.def(
      "format_verdict",
      [](const py::handle& verdict) {
        nlohmann::json j = FromPython(verdict, "verdict");
        const bool stated = !j.contains("stated") || j["stated"].get<bool>();
        j.erase("stated");
        j.erase("text");
        Verdict v = VerdictFromJson(j, "verdict");
        v.stated = stated;
        return FormatVerdict(v);
      },
      py::arg("verdict"));
  m.def(
      "model_from_dict",
      [](const py::handle& d, const std::string& source) {
        return model::ModelFromJson(FromPython(d, source), source);
      },
      py::arg("d"), py::arg("source") = "model");
  m.def("modal", &ModalDict, py::arg("model"));
  m.def(
      "frf",
      [](const model::Model& mo, int input_dof, int output_dof, const std::string& kind,
         const Eigen::Ref<const Eigen::VectorXd>& omega_rad_s) {
        const model::FrfKind k = model::ParseFrfKind(kind);
        py::gil_scoped_release release;
        return Eigen::VectorXcd(model::Frf(mo, input_dof, output_dof, k, omega_rad_s));
      },
      py::arg("model"), py::arg("input_dof"), py::arg("output_dof"), py::arg("kind"),
      py::arg("omega_rad_s"));
  m.def("simulate", &SimulateDict, py::arg("model"), py::arg("forces"), py::arg("dt_s"),
        py::arg("t_end_s"), py::arg("method"), py::arg("x0_m"), py::arg("v0_m_s"));
  m.def("read_recording", &ReadRecording, py::arg("path"), py::arg("fs_hz"), py::arg("time_column"),
        py::arg("channels"));
  m.def("write_csv", &WriteCsv, py::arg("path"), py::arg("names"), py::arg("data"),
        py::arg("sample_instants_us"), py::arg("facts_json") = py::none());
}

}  // namespace vibid::python
