#include "vibid/workflow/identify_run.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/option_text.hpp"
#include "vibid/ident/recording_columns.hpp"
#include "vibid/model/frf.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/workflow/result_json.hpp"
#include "vibid/workflow/sensor_calibration.hpp"

namespace vibid::workflow {

namespace {

/// The board's accelerometers (acc1, acc2): the default responses reach no further.
constexpr std::size_t kBoardAccelerometers = 2;

std::pair<std::size_t, std::string> ParsePositionAssignment(const std::string& text,
                                                            const std::string& option) {
  const auto eq = text.find('=');
  Require(eq != std::string::npos && eq > 0 && eq + 1 < text.size(),
          option + " '" + text + "' must be POSITION=VALUE (position counted from 1)");
  const std::string pos = text.substr(0, eq);
  const std::optional<long long> p = ParseInteger(pos);
  Require(p && *p >= 1, option + " '" + text + "': position '" + pos + "' is not a number >= 1");
  return {static_cast<std::size_t>(*p - 1), text.substr(eq + 1)};
}

nlohmann::json Triple(double nominal, double updated, double test) {
  return {{"nominal", nominal},
          {"updated", updated},
          {"test", test},
          {"nominal_dev_percent", ident::PercentDeviation(nominal, test)},
          {"updated_dev_percent", ident::PercentDeviation(updated, test)}};
}

nlohmann::json DeviationJson(const ident::ModalDeviation& d) {
  return {{"nominal_percent", d.nominal_percent},
          {"updated_percent", d.updated_percent},
          {"worse_than_nominal", d.worse_than_nominal}};
}

nlohmann::json PositionsJson(const std::vector<ident::PositionComparison>& rows) {
  nlohmann::json positions = nlohmann::json::array();
  for (const auto& p : rows) {
    nlohmann::json m = {{"nominal", p.m_nominal},
                        {"updated", p.m_updated},
                        {"change_percent", ident::PercentDeviation(p.m_updated, p.m_nominal)}};
    nlohmann::json k = {{"nominal", p.k_nominal},
                        {"updated", p.k_updated},
                        {"change_percent", ident::PercentDeviation(p.k_updated, p.k_nominal)}};
    nlohmann::json c = {{"updated", p.c_updated}};
    PutInterval(m, "updated", p.m_ci95);
    PutInterval(k, "updated", p.k_ci95);
    PutInterval(c, "updated", p.c_ci95);
    if (!p.m_source.empty()) {
      m["source"] = p.m_source;
      k["source"] = p.k_source;
      c["source"] = p.c_source;
    }
    positions.push_back({{"m_kg", m}, {"k_n_per_m", k}, {"c_ns_per_m", c}});
  }
  return positions;
}

std::vector<double> Std(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

nlohmann::json ValidationJson(const ident::ValidationTable& t,
                              const std::vector<ident::ModeEstimate>& test_modes,
                              std::size_t driving_point) {
  nlohmann::json modes = nlohmann::json::array();
  for (std::size_t i = 0; i < t.modes.size(); ++i) {
    const auto& m = t.modes[i];
    nlohmann::json row = {{"mode", m.mode + 1},
                          {"omega_rad_s", Triple(m.omega_nominal, m.omega_updated, m.omega_test)},
                          {"zeta", Triple(m.zeta_nominal, m.zeta_updated, m.zeta_test)}};
    // a1/a2 is the ratio of two responses; beyond two, each response against the driving
    // point's is a row of "shape_ratios" (a1/a3, a2/a3), as the text table has them.
    const bool two = m.shape_test.size() <= 2;
    if (two) row["ratio"] = Triple(m.ratio_nominal, m.ratio_updated, m.ratio_test);
    if (m.shape_test.size() > 0) {
      row["shape"] = {{"nominal", Std(m.shape_nominal)},
                      {"updated", Std(m.shape_updated)},
                      {"test", Std(m.shape_test)}};
    }
    const ident::ModeEstimate* e = i < test_modes.size() ? &test_modes[i] : nullptr;
    if (!two) {
      nlohmann::json ratios = nlohmann::json::array();
      const auto p = static_cast<Eigen::Index>(driving_point);
      for (Eigen::Index j = 0; j < m.shape_test.size(); ++j) {
        if (j == p) continue;
        nlohmann::json r = Triple(m.shape_nominal[j], m.shape_updated[j], m.shape_test[j]);
        r["name"] = "a" + std::to_string(j + 1) + "/a" + std::to_string(p + 1);
        const auto ju = static_cast<std::size_t>(j);
        if (e != nullptr && ju < e->shape_ratio_ci95.size() &&
            std::isfinite(e->shape_ratio_ci95[ju][0]) && std::isfinite(e->shape_ratio_ci95[ju][1]))
          r["test_ci95"] = {e->shape_ratio_ci95[ju][0], e->shape_ratio_ci95[ju][1]};
        ratios.push_back(r);
      }
      row["shape_ratios"] = ratios;
    }
    if (e != nullptr) {
      const std::pair<const char*, const std::array<double, 2>*> cis[] = {
          {"omega_rad_s", &e->omega_ci95_rad_s},
          {"zeta", &e->zeta_ci95},
          {"ratio", &e->ratio_ci95}};
      for (const auto& [key, ci] : cis) {
        if (row.contains(key) && std::isfinite((*ci)[0]) && std::isfinite((*ci)[1]))
          row[key]["test_ci95"] = {(*ci)[0], (*ci)[1]};
      }
    }
    modes.push_back(row);
  }
  nlohmann::json out = {{"method", t.method},
                        {"modes", modes},
                        {"positions", PositionsJson(t.positions)},
                        {"modal_deviation", DeviationJson(t.deviation)}};
  if (!t.caution.empty()) out["caution"] = t.caution;
  if (!t.beside.empty()) {
    out["beside"] = {{"method", t.beside_method},
                     {"positions", PositionsJson(t.beside)},
                     {"modal_deviation", DeviationJson(t.beside_deviation)}};
  }
  return out;
}

// The one-test chain fit: values, where each came from, the misfit, and (with the prior) the
// posterior-to-prior variance ratios; null when there is none.
nlohmann::json ChainFitJson(const ident::IdentifyResult& r) {
  if (!r.has_chain_fit) return nullptr;
  const ident::ChainFitResult& f = r.chain_fit;
  const auto n = static_cast<std::size_t>(f.masses_kg.size());
  nlohmann::json source = nlohmann::json::object();
  const char* keys[3] = {"m_kg", "k_n_per_m", "c_ns_per_m"};
  for (std::size_t q = 0; q < 3; ++q) {
    std::vector<std::string> s;
    for (std::size_t i = 0; i < n; ++i)
      s.push_back(ident::ParameterSourceName(f.source[q * n + i]));
    source[keys[q]] = s;
  }
  std::vector<std::size_t> seen;
  for (const Eigen::Index m : f.modes_seen) seen.push_back(static_cast<std::size_t>(m) + 1);
  nlohmann::json j = {{"masses", Std(f.masses_kg)},
                      {"springs", Std(f.springs_n_per_m)},
                      {"dampers", Std(f.dampers_ns_per_m)},
                      {"modes_seen", seen},
                      {"prior_used", f.prior_used},
                      {"source", source},
                      {"chi2", f.chi2},
                      {"dof", f.dof},
                      {"covariance_scale", f.covariance_scale},
                      {"summary", SolverSummaryJson(f.summary)}};
  if (f.prior_used) {
    nlohmann::json ratio = nlohmann::json::object();
    for (std::size_t q = 0; q < 3; ++q)
      ratio[keys[q]] = Std(f.prior_variance_ratio.segment(static_cast<Eigen::Index>(q * n),
                                                          static_cast<Eigen::Index>(n)));
    j["prior_variance_ratio"] = ratio;
  }
  return j;
}

// The updated parameters with their 95 % intervals, one object per position:
// {"position", "m_kg", "m_kg_ci95": [lo, hi] or null, "m_kg_ci95_basis" or "m_kg_ci95_missing",
// the same for k_n_per_m and c_ns_per_m}.
nlohmann::json ParametersJson(const ident::ValidationTable& t) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < t.positions.size(); ++i) {
    const auto& p = t.positions[i];
    nlohmann::json j = {{"position", i + 1},
                        {"m_kg", p.m_updated},
                        {"k_n_per_m", p.k_updated},
                        {"c_ns_per_m", p.c_updated}};
    PutInterval(j, "m_kg", p.m_ci95);
    PutInterval(j, "k_n_per_m", p.k_ci95);
    PutInterval(j, "c_ns_per_m", p.c_ci95);
    if (!p.m_source.empty()) {
      j["m_kg_source"] = p.m_source;
      j["k_n_per_m_source"] = p.k_source;
      j["c_ns_per_m_source"] = p.c_source;
    }
    out.push_back(j);
  }
  return out;
}

/// The springs of the mass tests: given (N/m), 0 for the nominal chain spring, or to be fitted.
struct MassSprings {
  std::vector<double> k_n_per_m;
  std::vector<bool> fit;
};

MassSprings ParseMassSprings(const std::vector<std::string>& specs, std::size_t n) {
  MassSprings out{std::vector<double>(n, 0.0), std::vector<bool>(n, false)};
  for (const std::string& s : specs) {
    const auto [pos, value] = ParsePositionAssignment(s, "--mass-spring");
    Require(pos < n, "--mass-spring position " + std::to_string(pos + 1) +
                         " is beyond the model's " + std::to_string(n) + " masses");
    if (value == "fit") {
      out.fit[pos] = true;
      continue;
    }
    double k = 0.0;
    Require(ParseNumber(value, k) == NumberText::kOk && k > 0.0,
            "--mass-spring '" + s + "': stiffness must be a number > 0");
    out.k_n_per_m[pos] = k;
  }
  return out;
}

/// Estimates one test; identify is made for hammer tests, so the processing note is said only
/// when a recording did not look like one.
ident::Frf EstimateTest(const std::string& path, const EstimationOptions& est, IdentifyRun& run,
                        ident::RingDowns* ringdowns = nullptr) {
  Estimated e = EstimateFromRecording(path, est);
  if (ringdowns != nullptr) *ringdowns = std::move(e.ringdowns);
  if (e.hits.empty() && !e.note.empty()) run.messages.push_back({false, e.note});
  for (const std::string& w : e.warnings) run.messages.push_back({true, w});
  const std::vector<std::string> lines = EstimationNotes(path, e);
  run.notes.insert(run.notes.end(), lines.begin(), lines.end());
  return std::move(e.frf);
}

std::vector<ident::MassTestInput> MassTests(const IdentifyRequest& a, const EstimationOptions& est,
                                            std::size_t n, IdentifyRun& run) {
  const MassSprings springs = ParseMassSprings(a.mass_springs, n);
  const std::vector<std::string> mass_responses =
      a.mass_response.empty() ? std::vector<std::string>{} : SplitOptionList(a.mass_response);
  Require(a.mass_response.empty() || mass_responses.size() == 1 ||
              mass_responses.size() == a.mass_tests.size(),
          "--mass-response names " + std::to_string(mass_responses.size()) + " columns for " +
              std::to_string(a.mass_tests.size()) +
              " mass tests (give one for all, or one per test)");
  // --sensor names one quantity for all, or one per mass in mass order (the modal tests'
  // responses): a mass test takes its mass's.
  const std::vector<std::string> sensors =
      est.sensor.empty() ? std::vector<std::string>{} : SplitOptionList(est.sensor);
  Require(sensors.size() <= 1 || sensors.size() == n,
          "--sensor names " + std::to_string(sensors.size()) + " quantities for a chain of " +
              std::to_string(n) + " masses (give one for all, or one per mass in mass order)");
  std::vector<ident::MassTestInput> inputs;
  for (std::size_t t = 0; t < a.mass_tests.size(); ++t) {
    const MassTestFile& test = a.mass_tests[t];
    Require(test.position < n, "--mass-test position " + std::to_string(test.position + 1) +
                                   " is beyond the model's " + std::to_string(n) + " masses");
    EstimationOptions me = est;
    // By default the accelerometer on the tested mass, as `acquire --channels force1,accP` names
    // it; the board has two, so a mass beyond them names its response.
    Require(!mass_responses.empty() || test.position < kBoardAccelerometers,
            "--mass-test " + std::to_string(test.position + 1) +
                ": the board's accelerometers acc1 and acc2 are on masses 1 and 2 by default; "
                "name the response of mass " +
                std::to_string(test.position + 1) +
                " with --mass-response (e.g. x1_m for an encoder)");
    if (sensors.size() > 1) me.sensor = sensors[test.position];
    me.responses = mass_responses.empty()       ? ident::AccelerationColumn(test.position + 1)
                   : mass_responses.size() == 1 ? mass_responses[0]
                                                : mass_responses[t];
    inputs.push_back({test.position, EstimateTest(test.path, me, run),
                      springs.k_n_per_m[test.position], springs.fit[test.position]});
  }
  return inputs;
}

}  // namespace

IdentifyRequest DefaultIdentifyRequest() {
  IdentifyRequest r;
  r.estimation.force = ident::ForceColumn();
  return r;
}

MassTestFile ParseMassTest(const std::string& text) {
  const auto [pos, path] = ParsePositionAssignment(text, "--mass-test");
  return {pos, path};
}

ident::DrivingPointChoice DrivingPointOfTests(const std::vector<ident::Frf>& modal_frfs,
                                              const ModeRequest& modes,
                                              const ident::ModeIdentificationOptions& options,
                                              const std::vector<ident::RingDowns>& ringdowns) {
  ident::DrivingPointChoice first;
  for (std::size_t t = 0; t < modal_frfs.size(); ++t) {
    const ident::Frf& frf = modal_frfs[t];
    const std::optional<ident::NamedDrivingPoint> named = NamedDrivingPointOf(frf, modes);
    const ident::ModeIdentification m =
        ident::IdentifyModes(frf, named ? named->index : 0, options);
    ident::DrivingPointChoice c;
    try {
      c = ChooseDrivingPointOf(frf, m, named, t < ringdowns.size() ? &ringdowns[t] : nullptr);
    } catch (const InputError& e) {
      throw InputError((modal_frfs.size() > 1 ? "modal test " + std::to_string(t + 1) + ": " : "") +
                       e.what());
    }
    if (t == 0) {
      first = std::move(c);
      continue;
    }
    Require(c.index == first.index,
            "the modal tests were hit at different points (test 1 at response " +
                std::to_string(first.index + 1) + ", test " + std::to_string(t + 1) +
                " at response " + std::to_string(c.index + 1) +
                "): identify takes tests of one driving point; give the tests of one point");
  }
  return first;
}

IdentifyRun RunIdentify(const model::Model& nominal, const IdentifyRequest& request) {
  const auto n = static_cast<std::size_t>(nominal.dofs());
  Require(!request.modal_tests.empty(), "--modal-test: at least one modal test is needed");
  EstimationOptions est = request.estimation;
  est.impact = false;  // each recording is classified by its force channel unless welch is set
  est.kind = "receptance";
  IdentifyRun run;
  const std::vector<ident::MassTestInput> mass_inputs = MassTests(request, est, n, run);
  std::vector<ident::RingDowns> ringdowns;
  for (const std::string& path : request.modal_tests) {
    EstimationOptions me = est;
    Require(!request.modal_responses.empty() || n <= kBoardAccelerometers,
            "--modal-test: a chain of " + std::to_string(n) +
                " masses, and the board's two accelerometers measure masses 1 and 2 by default; "
                "name the response of each mass, in mass order, with --modal-responses (e.g. "
                "acc1_m_s2,acc2_m_s2,x1_m: accelerometers and encoders may be mixed)");
    me.responses =
        request.modal_responses.empty() ? ident::AccelerationColumns(n) : request.modal_responses;
    ident::RingDowns rd;
    run.modal_frfs.push_back(EstimateTest(path, me, run, &rd));
    ringdowns.push_back(std::move(rd));
  }
  ident::IdentifyOptions options;
  // The modes of each test take the amplitude check on its own hits, as `vibid modes` does.
  options.modal_ringdowns = std::move(ringdowns);
  options.modes = request.modes.options;
  options.modes.method = ident::ParseModeMethod(request.modes.method);
  if (!request.modes.orders.empty())
    ident::ParseOrders(request.modes.orders, options.modes.stabilization);
  run.driving_point_choice =
      DrivingPointOfTests(run.modal_frfs, request.modes, options.modes, options.modal_ringdowns);
  run.driving_point = run.driving_point_choice.index;
  run.messages.push_back({false, run.driving_point_choice.note});
  for (const std::string& w : run.driving_point_choice.warnings) run.messages.push_back({true, w});
  options.driving_point = run.driving_point;
  options.chain.prior_relative_sd = request.prior_relative_sd;
  run.result = ident::Identify(nominal, mass_inputs, run.modal_frfs, options);
  if (!request.sensors.empty()) {
    // The sensor on each mass: the mass test's response where there is one, else the modal
    // tests' response of that mass.
    std::vector<std::string> responses = request.modal_responses.empty()
                                             ? SplitOptionList(ident::AccelerationColumns(n))
                                             : SplitOptionList(request.modal_responses);
    for (const ident::MassTestInput& m : mass_inputs) {
      if (m.position < responses.size() && !m.receptance.response_names.empty())
        responses[m.position] = m.receptance.response_names.front();
    }
    std::vector<std::string> warnings;
    const std::vector<PositionCalibration> calibration = CalibrationOfPositions(
        device::SensorsFromJson(ReadJsonFile(request.sensors), request.sensors), est.force,
        responses, warnings);
    for (const std::string& w : warnings) run.messages.push_back({true, w});
    AddSensorCalibration(run.result.table, calibration);
  }
  return run;
}

nlohmann::json ChainJson(const ident::ChainParameters& chain, std::size_t n) {
  const auto list = [n](const Eigen::VectorXd& v) {
    return std::vector<double>(v.data(), v.data() + n);
  };
  return {{"topology", "chain"},
          {"masses", list(chain.masses_kg)},
          {"springs", list(chain.springs_n_per_m)},
          {"dampers", list(chain.dampers_ns_per_m)}};
}

nlohmann::json UpdatedModelJson(const IdentifyRun& run, std::size_t n) {
  nlohmann::json model_json = ChainJson(run.result.chain, n);
  model::PutVerdict(model_json, run.result.verdict);
  return model_json;
}

std::string ValidationText(const IdentifyRun& run) {
  return ident::FormatValidationTable(run.result.table) +
         "Verdict: " + FormatVerdict(run.result.verdict) + "\n";
}

void WriteUpdatedModel(const IdentifyRun& run, std::size_t n, const std::string& path,
                       bool accept_flagged, const std::string& option) {
  const Verdict& v = run.result.verdict;
  if (v.Flagged() && !accept_flagged) {
    std::string reasons;
    for (const VerdictReason& r : v.reasons)
      if (r.level == VerdictLevel::kFlagged) reasons += (reasons.empty() ? "" : "; ") + r.text;
    throw FlaggedError("the identification is flagged (" + reasons + "): " + path +
                       " was not written; " + option +
                       " writes it anyway, the file then carrying the verdict");
  }
  WriteJsonFile(path, UpdatedModelJson(run, n));
}

nlohmann::json IdentifyReportJson(const IdentifyRun& run, std::size_t n) {
  const ident::IdentifyResult& r = run.result;
  const std::vector<std::string>& notes = run.notes;
  nlohmann::json report;
  report["verdict"] = VerdictToJson(r.verdict);
  report["updated_model"] = UpdatedModelJson(run, n);
  report["validation"] = ValidationJson(r.table, r.test_modes, run.driving_point);
  report["parameters"] = ParametersJson(r.table);
  report["test_modes"] = ModesToJson(r.test_modes)["modes"];
  nlohmann::json masses = nlohmann::json::array();
  for (const auto& m : r.mass_tests) {
    nlohmann::json j = MassUpdateJson(m.update);
    j["position"] = m.position + 1;
    masses.push_back(j);
  }
  report["mass_tests"] = masses;
  nlohmann::json modal_json = nlohmann::json::array();
  for (const auto& mt : r.modal_tests) {
    nlohmann::json j = ModesToJson(mt.modes);
    if (mt.fitted) j["summary"] = SolverSummaryJson(mt.fit.summary);
    if (mt.has_diagram) j["stabilization"] = DiagramToJson(mt.diagram);
    modal_json.push_back(j);
  }
  report["modal_tests"] = modal_json;
  report["method"] = r.method;
  report["driving_point"] = {
      {"response", run.driving_point + 1},
      {"name", run.driving_point < run.modal_frfs.front().response_names.size()
                   ? run.modal_frfs.front().response_names[run.driving_point]
                   : std::string()},
      {"how", run.driving_point_choice.how},
      {"note", run.driving_point_choice.note}};
  report["chain_fit"] = ChainFitJson(r);
  report["stiffness"] =
      r.stiffness.tests.empty() ? nlohmann::json(nullptr) : StiffnessJson(r.stiffness);
  report["warnings"] = r.warnings;
  report["notes"] = notes;
  return report;
}

std::string FrfOverlayCsv(const IdentifyRun& run, const model::Model& nominal) {
  const ident::Frf& measured = run.modal_frfs.front();
  const std::size_t driving_point = run.driving_point;
  const model::Model& updated = run.result.updated;
  const Eigen::VectorXd omega = 2.0 * std::numbers::pi * measured.freq_hz;
  std::vector<std::string> names{"freq_hz"};
  std::vector<Eigen::VectorXd> cols{measured.freq_hz};
  for (Eigen::Index j = 0; j < measured.h.cols(); ++j) {
    const std::string base = "h" + std::to_string(j + 1) + std::to_string(driving_point + 1);
    names.push_back(base + "_test");
    cols.push_back(measured.h.col(j).cwiseAbs());
    names.push_back(base + "_nominal");
    cols.push_back(model::Frf(nominal, static_cast<int>(driving_point), static_cast<int>(j),
                              model::FrfKind::kReceptance, omega)
                       .cwiseAbs());
    names.push_back(base + "_updated");
    cols.push_back(model::Frf(updated, static_cast<int>(driving_point), static_cast<int>(j),
                              model::FrfKind::kReceptance, omega)
                       .cwiseAbs());
  }
  return FormatCsv(names, cols);
}

}  // namespace vibid::workflow
