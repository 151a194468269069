// FRF estimation, modes and the identify run through the workflow library, as `vibid
// frf-estimate`, `vibid modes` and `vibid identify` call it. Signals come in as numpy views:
// a float64 C-ordered (channels, samples) array is a column-major (samples, channels) matrix, so
// Eigen reads it in place.
#include <optional>

#include <pybind11/complex.h>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/identify.hpp"
#include "vibid/model/model.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/workflow/decay_run.hpp"
#include "vibid/workflow/report_page.hpp"
#include "vibid/workflow/estimate.hpp"
#include "vibid/workflow/identify_run.hpp"
#include "vibid/workflow/modes_request.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::python {
namespace {

using Signals = py::array_t<double, py::array::c_style>;

py::dict FrfDict(const ident::Frf& f) {
  py::dict d;
  d["freq_hz"] = f.freq_hz;
  d["h"] = f.h;
  d["coherence"] = f.coherence;
  d["kind"] = ident::FrfKindName(f.quantity);
  d["estimator"] = ident::EstimatorName(f.estimator);
  d["averages"] = f.averages;
  d["responses"] = f.response_names;
  d["force"] = f.force_name;
  return d;
}

py::dict EstimatedDict(const workflow::Estimated& e) {
  py::dict d = FrfDict(e.frf);
  py::list hits;
  for (const ident::Hit& h : e.hits) {
    py::dict hit;
    hit["t_s"] = h.t_s;
    hit["peak_n"] = h.peak_n;
    hit["pulse_width_s"] = h.pulse_width_s;
    hit["double_hit"] = h.double_hit;
    hit["clipped"] = h.clipped;
    hit["truncated"] = h.truncated;
    hit["used"] = h.used;
    hit["note"] = h.note;
    hits.append(hit);
  }
  d["hits"] = hits;
  d["impact"] = e.impact;
  d["note"] = e.note;
  d["warnings"] = e.warnings;
  d["compensation"] = e.compensation;
  d["record_samples"] = e.record_samples;
  // The library's FRF itself, kept with the arrays: modes on it later see every field the
  // estimation set (windows, pretrigger, level variance), as `vibid modes` on a recording does.
  d["_frf"] = py::cast(e.frf);
  // The used hits' ring-downs, so that modes of this estimate make the amplitude check too.
  d["_ringdowns"] = py::cast(e.ringdowns);
  return d;
}

py::dict EstimateFile(const std::string& path, const workflow::EstimationOptions& options) {
  workflow::Estimated e;
  {
    py::gil_scoped_release release;
    e = workflow::EstimateFromRecording(path, options);
  }
  return EstimatedDict(e);
}

py::dict EstimateArrays(const Signals& force, const Signals& responses, double fs_hz,
                        const std::string& force_name,
                        const std::vector<std::string>& response_names,
                        const workflow::EstimationOptions& options,
                        const std::vector<double>& instants_s,
                        const std::vector<std::pair<double, double>>& rails) {
  Require(force.ndim() == 1,
          "force must be 1-D (samples), not " + std::to_string(force.ndim()) + "-D");
  Require(responses.ndim() == 2, "responses must be 2-D (responses, samples), not " +
                                     std::to_string(responses.ndim()) + "-D");
  const Eigen::Map<const Eigen::VectorXd> f(force.data(), force.shape(0));
  const Eigen::Map<const Eigen::MatrixXd> x(responses.data(), responses.shape(1),
                                            responses.shape(0));
  // The converters' rails the recording's facts state (force first), for the clip check;
  // without them it is unavailable, and the estimate's warnings say so.
  workflow::EstimationOptions o = options;
  if (!rails.empty()) {
    Require(rails.size() == response_names.size() + 1,
            "rails: one (low, high) per channel, the force first");
    o.impact_options.converter_limits.clear();
    for (const auto& [lo, hi] : rails) o.impact_options.converter_limits.push_back({lo, hi});
  }
  workflow::Estimated e;
  {
    py::gil_scoped_release release;
    e = workflow::EstimateFromSignals(f, x, fs_hz, force_name, response_names, o, instants_s);
  }
  return EstimatedDict(e);
}

py::object Modes(const std::vector<std::string>& inputs, const workflow::EstimationOptions& options,
                 const workflow::ModeRequest& request) {
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    const workflow::ModesOfInputs m = workflow::IdentifyModesOf(inputs, options, request);
    j = workflow::ModeIdentificationJson(m.identification, request.method, m.frf.response_names,
                                         m.notes);
  }
  return ToPython(j);
}

/// Modes of FRFs already in memory (each an estimate's own FRF, or one built from arrays), joined
/// as responses, as `vibid modes` joins its inputs.
py::object ModesOf(const std::vector<ident::Frf>& frfs, const std::vector<std::string>& sources,
                   const workflow::ModeRequest& request,
                   const std::optional<ident::RingDowns>& ringdowns) {
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    Require(!frfs.empty(), "no FRF given");
    for (const ident::Frf& f : frfs)
      Require(f.quantity == ident::Quantity::kDisplacement,
              "modes are identified from receptances; estimate with kind='receptance'");
    const ident::Frf frf = workflow::JoinColumns(frfs, sources);
    // One estimate's ring-downs, as `vibid modes` on its recording checks them.
    const ident::ModeIdentification r = workflow::IdentifyModes(
        frf, request, frfs.size() == 1 && ringdowns ? &*ringdowns : nullptr);
    j = workflow::ModeIdentificationJson(r, request.method, frf.response_names, {});
  }
  return ToPython(j);
}

/// An FRF from arrays (a receptance, mobility or accelerance `kind`): h lines x responses,
/// coherence likewise (None: 1), uniform lines; what a FRF file without its estimation's extra
/// columns gives.
ident::Frf FrfFromArrays(const Eigen::VectorXd& freq_hz, const Eigen::MatrixXcd& h,
                         const std::optional<Eigen::MatrixXd>& coherence, const std::string& kind,
                         const std::vector<std::string>& responses, const std::string& force) {
  Require(freq_hz.size() >= 2, "an FRF needs at least two frequency lines");
  Require(h.rows() == freq_hz.size(), "h has " + std::to_string(h.rows()) + " lines, freq_hz " +
                                          std::to_string(freq_hz.size()) +
                                          "; give h shaped (n_out, 1, n_freq)");
  Require(static_cast<std::size_t>(h.cols()) == responses.size(),
          std::to_string(responses.size()) + " output names for " + std::to_string(h.cols()) +
              " outputs");
  Require(freq_hz.allFinite() && h.allFinite(), "freq_hz and h must hold finite numbers");
  ident::Frf f;
  f.freq_hz = freq_hz;
  f.h = h;
  f.coherence = coherence ? *coherence : Eigen::MatrixXd::Ones(h.rows(), h.cols());
  Require(f.coherence.rows() == h.rows() && f.coherence.cols() == h.cols(),
          "coherence must be shaped as h");
  f.quantity = ident::ParseQuantity(kind);
  f.response_names = responses;
  f.force_name = force;
  return f;
}

py::tuple Identify(const model::Model& nominal, const workflow::IdentifyRequest& request) {
  nlohmann::json report;
  nlohmann::json chain;
  std::string table;
  {
    py::gil_scoped_release release;
    const workflow::IdentifyRun run = workflow::RunIdentify(nominal, request);
    const auto n = static_cast<std::size_t>(nominal.dofs());
    report = workflow::IdentifyReportJson(run, n);
    chain = workflow::UpdatedModelJson(run, n);
    table = workflow::ValidationText(run);
  }
  return py::make_tuple(ToPython(chain), ToPython(report), table);
}

}  // namespace

void RegisterAnalysis(py::module_& m) {
  using O = workflow::EstimationOptions;
  py::class_<O>(m, "_EstimationOptions")
      .def(py::init<>())
      .def_readwrite("force", &O::force)
      .def_readwrite("responses", &O::responses)
      .def_readwrite("estimator", &O::estimator)
      .def_readwrite("impact", &O::impact)
      .def_readwrite("welch", &O::welch)
      .def_readwrite("window", &O::window)
      .def_readwrite("detrend", &O::detrend)
      .def_readwrite("sensor", &O::sensor)
      .def_readwrite("kind", &O::kind)
      .def_readwrite("segment", &O::segment)
      .def_readwrite("overlap", &O::overlap)
      .def_readwrite("fs_hz", &O::fs_hz)
      .def_readwrite("keep_bad_hits", &O::keep_bad_hits)
      .def_property(
          "exp_window_end", [](const O& o) { return o.impact_options.exp_window_end; },
          [](O& o, double v) { o.impact_options.exp_window_end = v; })
      .def_property(
          "record_s", [](const O& o) { return o.impact_options.record_s; },
          [](O& o, double v) { o.impact_options.record_s = v; })
      .def_property(
          "pretrigger_s", [](const O& o) { return o.impact_options.pretrigger_s; },
          [](O& o, double v) { o.impact_options.pretrigger_s = v; })
      .def("validate", &O::Validate);
  using R = workflow::ModeRequest;
  py::class_<R>(m, "_ModeRequest")
      .def(py::init<>())
      .def_readwrite("method", &R::method)
      .def_readwrite("orders", &R::orders)
      .def_readwrite("driving_point", &R::driving_point)
      .def_readwrite("driving_point_source", &R::driving_point_source)
      .def_property(
          "fmin_hz", [](const R& r) { return r.options.peaks.freq_min_hz; },
          [](R& r, double v) { r.options.peaks.freq_min_hz = v; })
      .def_property(
          "fmax_hz", [](const R& r) { return r.options.peaks.freq_max_hz; },
          [](R& r, double v) { r.options.peaks.freq_max_hz = v; });
  using I = workflow::IdentifyRequest;
  py::class_<I>(m, "_IdentifyRequest")
      .def(py::init(&workflow::DefaultIdentifyRequest))
      .def("add_mass_test",
           [](I& r, const std::string& text) {
             r.mass_tests.push_back(workflow::ParseMassTest(text));
           })
      .def_readwrite("mass_springs", &I::mass_springs)
      .def_readwrite("modal_tests", &I::modal_tests)
      .def_readwrite("mass_response", &I::mass_response)
      .def_readwrite("modal_responses", &I::modal_responses)
      .def_readwrite("estimation", &I::estimation)
      .def_readwrite("modes", &I::modes);
  using D = workflow::DecayRequest;
  py::class_<D>(m, "_DecayRequest")
      .def(py::init<>())
      .def_readwrite("recordings", &D::recordings)
      .def_readwrite("loaded", &D::loaded)
      .def_readwrite("position", &D::position)
      .def_readwrite("scale", &D::scale)
      .def_readwrite("fs_hz", &D::fs_hz)
      .def_readwrite("added_kg", &D::added_kg)
      .def_property(
          "cycles", [](const D& d) { return d.options.cycles; },
          [](D& d, int v) { d.options.cycles = v; })
      .def_property(
          "end_fraction", [](const D& d) { return d.options.end_fraction; },
          [](D& d, double v) { d.options.end_fraction = v; });
  m.def(
      "decay",
      [](const D& request) {
        nlohmann::json j;
        {
          py::gil_scoped_release release;
          j = workflow::RunDecay(request);
        }
        return ToPython(j);
      },
      py::arg("request"));
  using Rep = workflow::ReportRequest;
  py::class_<Rep>(m, "_ReportRequest")
      .def(py::init<>())
      .def_readwrite("title", &Rep::title)
      .def_readwrite("identify_dir", &Rep::identify_dir)
      .def_readwrite("accept_flagged", &Rep::accept_flagged)
      .def_readwrite("truth", &Rep::truth)
      .def_readwrite("dob_recording", &Rep::dob_recording)
      .def_readwrite("measured", &Rep::measured)
      .def_readwrite("estimates", &Rep::estimates)
      .def_readwrite("skip_s", &Rep::skip_s)
      .def_readwrite("notes", &Rep::notes);
  m.def(
      "report",
      [](const Rep& request, const std::string& output) {
        py::gil_scoped_release release;
        WriteFileAtomic(output, workflow::ReportPage(request));
      },
      py::arg("request"), py::arg("output"));
  m.def("estimate_file", &EstimateFile, py::arg("path"), py::arg("options"));
  m.def("estimate_arrays", &EstimateArrays, py::arg("force").noconvert(false), py::arg("responses"),
        py::arg("fs_hz"), py::arg("force_name"), py::arg("response_names"), py::arg("options"),
        py::arg("instants_s"), py::arg("rails") = std::vector<std::pair<double, double>>{});
  m.def("default_segment", &workflow::DefaultSegment, py::arg("samples"));
  m.def("modes", &Modes, py::arg("inputs"), py::arg("options"), py::arg("request"));
  py::class_<ident::Frf>(m, "_Frf");
  py::class_<ident::RingDowns>(m, "_RingDowns");
  m.def("modes_of", &ModesOf, py::arg("frfs"), py::arg("sources"), py::arg("request"),
        py::arg("ringdowns") = std::nullopt);
  m.def("frf_from_arrays", &FrfFromArrays, py::arg("freq_hz"), py::arg("h"), py::arg("coherence"),
        py::arg("kind"), py::arg("responses"), py::arg("force"));
  m.def("identify", &Identify, py::arg("nominal"), py::arg("request"));
}

}  // namespace vibid::python
