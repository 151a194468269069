// `vibid identify`: the whole chain from hammer recordings to an updated model file.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "common/option_text.hpp"
#include "common/solver_json.hpp"
#include "ident_cli.hpp"
#include "ident_commands.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/ident/identify.hpp"
#include "vibid/ident/recording_columns.hpp"
#include "vibid/model/frf.hpp"
#include "vibid/model/model_json.hpp"

namespace vibid::cli {

namespace {

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

nlohmann::json ValidationJson(const ident::ValidationTable& t,
                              const std::vector<ident::ModeEstimate>& test_modes) {
  nlohmann::json modes = nlohmann::json::array();
  for (std::size_t i = 0; i < t.modes.size(); ++i) {
    const auto& m = t.modes[i];
    nlohmann::json row = {{"omega_rad_s", Triple(m.omega_nominal, m.omega_updated, m.omega_test)},
                          {"zeta", Triple(m.zeta_nominal, m.zeta_updated, m.zeta_test)},
                          {"ratio", Triple(m.ratio_nominal, m.ratio_updated, m.ratio_test)}};
    if (i < test_modes.size()) {
      const ident::ModeEstimate& e = test_modes[i];
      const std::pair<const char*, const std::array<double, 2>*> cis[] = {
          {"omega_rad_s", &e.omega_ci95_rad_s}, {"zeta", &e.zeta_ci95}, {"ratio", &e.ratio_ci95}};
      for (const auto& [key, ci] : cis) {
        if (std::isfinite((*ci)[0]) && std::isfinite((*ci)[1]))
          row[key]["test_ci95"] = {(*ci)[0], (*ci)[1]};
      }
    }
    modes.push_back(row);
  }
  nlohmann::json positions = nlohmann::json::array();
  for (const auto& p : t.positions) {
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
    positions.push_back({{"m_kg", m}, {"k_n_per_m", k}, {"c_ns_per_m", c}});
  }
  return {{"modes", modes}, {"positions", positions}};
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
    out.push_back(j);
  }
  return out;
}

// Measured receptance of the first modal test beside the nominal and updated models' receptances
// (hammer at the driving point), magnitudes per response.
std::string OverlayCsv(const ident::Frf& measured, std::size_t driving_point,
                       const model::Model& nominal, const model::Model& updated) {
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

constexpr const char* kIdentifyHelp =
    "The whole identification: effective masses from 1-DOF hammer tests (--mass-test POS=REC), "
    "modes from\n"
    "hammer tests of the chain (--modal-test REC, hammer at the driving point), stiffness and "
    "damping from the\n"
    "modes with the updated masses averaged over the tests; writes the updated chain model and "
    "prints the\n"
    "validation table (nominal, updated, test).";

struct IdentifyArgs {
  std::string nominal;
  std::vector<std::string> mass_tests;
  std::vector<std::string> mass_springs;
  std::vector<std::string> modal_tests;
  /// Empty: the board's names (ident/recording_columns.hpp): mass test of position P reads
  /// accP_m_s2, the modal tests acc1_m_s2 ... accN_m_s2.
  std::string mass_response;
  std::string modal_responses;
  std::string output;
  std::string report;
  bool welch = false;
  EstimationArgs est;  ///< Its force column defaults to the board's force1_n (set at registration).
  ModeArgs modes;
};

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

// identify is made for hammer tests: the processing note is said only when a recording did not
// look like one.
ident::Frf EstimateTest(const std::string& path, const EstimationArgs& est,
                        std::vector<std::string>& notes) {
  Estimated e = EstimateFromRecording(path, est);
  KeepEstimationNotes(path, e, e.hits.empty(), notes);
  return std::move(e.frf);
}

std::vector<ident::MassTestInput> MassTests(const IdentifyArgs& a, const EstimationArgs& est,
                                            std::size_t n, std::vector<std::string>& notes) {
  const MassSprings springs = ParseMassSprings(a.mass_springs, n);
  const std::vector<std::string> mass_responses =
      a.mass_response.empty() ? std::vector<std::string>{} : SplitOptionList(a.mass_response);
  Require(a.mass_response.empty() || mass_responses.size() == 1 ||
              mass_responses.size() == a.mass_tests.size(),
          "--mass-response names " + std::to_string(mass_responses.size()) + " columns for " +
              std::to_string(a.mass_tests.size()) +
              " mass tests (give one for all, or one per test)");
  std::vector<ident::MassTestInput> inputs;
  for (std::size_t t = 0; t < a.mass_tests.size(); ++t) {
    const auto [pos, path] = ParsePositionAssignment(a.mass_tests[t], "--mass-test");
    Require(pos < n, "--mass-test position " + std::to_string(pos + 1) + " is beyond the model's " +
                         std::to_string(n) + " masses");
    EstimationArgs me = est;
    // By default the accelerometer on the tested mass, as `acquire --channels force1,accP` names
    // it.
    me.responses = mass_responses.empty()       ? ident::AccelerationColumn(pos + 1)
                   : mass_responses.size() == 1 ? mass_responses[0]
                                                : mass_responses[t];
    inputs.push_back(
        {pos, EstimateTest(path, me, notes), springs.k_n_per_m[pos], springs.fit[pos]});
  }
  return inputs;
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

nlohmann::json ReportJson(const ident::IdentifyResult& r, const nlohmann::json& model_json,
                          const std::vector<std::string>& notes) {
  nlohmann::json report;
  report["updated_model"] = model_json;
  report["validation"] = ValidationJson(r.table, r.test_modes);
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
  report["stiffness"] = StiffnessJson(r.stiffness);
  report["warnings"] = r.warnings;
  report["notes"] = notes;
  return report;
}

void Run(const IdentifyArgs& a) {
  const model::Model nominal = model::LoadModel(a.nominal);
  const auto n = static_cast<std::size_t>(nominal.dofs());
  EstimationArgs est = a.est;
  est.impact = false;
  est.welch = a.welch;  // otherwise each recording is classified by its force channel
  est.kind = "receptance";
  std::vector<std::string> notes;
  const std::vector<ident::MassTestInput> mass_inputs = MassTests(a, est, n, notes);
  std::vector<ident::Frf> modal;
  for (const std::string& path : a.modal_tests) {
    EstimationArgs me = est;
    me.responses = a.modal_responses.empty() ? ident::AccelerationColumns(n) : a.modal_responses;
    modal.push_back(EstimateTest(path, me, notes));
  }
  ident::IdentifyOptions options;
  options.modes = a.modes.options;
  options.modes.method = ident::ParseModeMethod(a.modes.method);
  if (!a.modes.orders.empty()) ident::ParseOrders(a.modes.orders, options.modes.stabilization);
  options.driving_point = ResolveDrivingPoint(modal.front(), a.modes.driving_point);
  const ident::IdentifyResult r = ident::Identify(nominal, mass_inputs, modal, options);

  const nlohmann::json model_json = ChainJson(r.chain, n);
  const std::string table = ident::FormatValidationTable(r.table);
  if (!a.report.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(a.report, ec);
    Require(!ec && std::filesystem::is_directory(a.report),
            "--report: cannot create directory '" + a.report + "'");
    const std::filesystem::path dir(a.report);
    WriteFileAtomic((dir / "validation.txt").string(), table);
    WriteJsonFile((dir / "report.json").string(), ReportJson(r, model_json, notes));
    WriteFileAtomic((dir / "frf_overlay.csv").string(),
                    OverlayCsv(modal.front(), options.driving_point, nominal, r.updated));
  }
  WriteJsonFile(a.output, model_json);
  std::cout << table;
  for (const auto& w : r.warnings) std::cerr << "vibid: warning: " << w << "\n";
}

}  // namespace

void RegisterIdentify(CLI::App& app) {
  const auto [cmd, a] = AddCommand<IdentifyArgs>(app, "identify", kIdentifyHelp, Run);
  a->est.force = ident::ForceColumn();
  cmd->add_option("--nominal", a->nominal, "Nominal model file (JSON; a chain)")->required();
  cmd->add_option("--mass-test", a->mass_tests,
                  "POS=REC.csv: mass POS (from 1) alone on its spring, hammer test");
  cmd->add_option(
      "--mass-spring", a->mass_springs,
      "POS=K: spring (N/m) of that mass test, when it is not the nominal chain spring of POS;\n"
      "POS=fit: not known, fitted with the mass");
  cmd->add_option("--modal-test", a->modal_tests,
                  "REC.csv: hammer test of the chain; repeat for several tests")
      ->required();
  cmd->add_option("--force", a->est.force, "Force column in every recording")
      ->capture_default_str();
  cmd->add_option("--mass-response", a->mass_response,
                  "Response column of the mass tests: one for all, or one per --mass-test in order "
                  "(comma separated); default accP_m_s2 for the test of mass P, as acquire names "
                  "it");
  cmd->add_option("--modal-responses", a->modal_responses,
                  "Response columns of the modal tests, one per mass in order; default acc1_m_s2,"
                  "...,accN_m_s2 for N masses, as acquire names them");
  cmd->add_option("--sensor", a->est.sensor, "What the response channels measure: acc, vel, disp")
      ->capture_default_str();
  cmd->add_option("--estimator", a->est.estimator, "FRF estimator: h1, h2, hv")
      ->capture_default_str();
  cmd->add_flag(
      "--welch", a->welch,
      "Welch averaging even for recordings whose force looks like hammer hits (default: per-hit\n"
      "records for hammer tests, Welch for random/periodic excitation, decided per recording)");
  cmd->add_option("--exp-window", a->est.impact_options.exp_window_end,
                  "Exponential window value at the end of each hit record (0: none); damping is "
                  "corrected for it")
      ->check(NonNegativeNumber());
  cmd->add_option("--record-s", a->est.impact_options.record_s,
                  "Length of each hit's record, s (default: the shortest hit spacing)")
      ->check(NonNegativeNumber());
  cmd->add_option("--trigger", a->est.impact_options.trigger_fraction,
                  "Hit threshold as a fraction of the largest force")
      ->capture_default_str();
  cmd->add_flag("--keep-bad-hits", a->est.keep_bad_hits,
                "Use double and clipped hits (only flag them)");
  cmd->add_option("--fs-hz", a->est.fs_hz, "Sample rate (Hz) when recordings have no t_s column")
      ->check(PositiveNumber());
  AddModeOptions(cmd, a->modes);
  cmd->add_option("-o,--output", a->output, "Updated model file (JSON, chain form)")->required();
  cmd->add_option("--report", a->report,
                  "Directory for the report: validation.txt, report.json (all results), "
                  "frf_overlay.csv (test vs models)");
}

}  // namespace vibid::cli
