// `vibid update mass` and `vibid update stiffness`.
#include <array>
#include <iostream>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/common/option_text.hpp"
#include "common/solver_json.hpp"
#include "ident_cli.hpp"
#include "ident_commands.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/device/calibration_builder.hpp"
#include "vibid/ident/updates.hpp"
#include "vibid/workflow/result_json.hpp"
#include "vibid/workflow/sensor_calibration.hpp"

namespace vibid::cli {

namespace {

std::vector<double> ParsePositiveList(const std::string& text, const std::string& what) {
  std::vector<double> out;
  for (const std::string& item : SplitOptionList(text, TrailingEmpty::kDrop)) {
    double v = 0.0;
    Require(ParseNumber(item, v) == NumberText::kOk && v > 0.0,
            what + ": '" + item + "' is not a positive number");
    out.push_back(v);
  }
  Require(!out.empty(), what + " is empty");
  return out;
}

// The masses' uncertainties: from --mass-ci95 (95 % half-widths, normal), else taken as exact.
std::vector<ident::Uncertainty> MassUncertainties(const std::string& text, std::size_t n) {
  if (text.empty()) {
    return std::vector<ident::Uncertainty>(
        n, ident::Uncertainty::ExactValue("masses taken as exact (--mass-ci95 adds theirs)"));
  }
  const std::vector<double> hw = ParsePositiveList(text, "--mass-ci95");
  Require(hw.size() == n, "--mass-ci95 gives " + std::to_string(hw.size()) + " half-widths for " +
                              std::to_string(n) + " masses");
  std::vector<ident::Uncertainty> out;
  for (double h : hw) {
    ident::Uncertainty u;
    u.variance = (h / ident::kZ95) * (h / ident::kZ95);
    u.basis = "--mass-ci95";
    out.push_back(u);
  }
  return out;
}

}  // namespace

ident::StiffnessUpdateResult StiffnessFromModes(const Eigen::VectorXd& masses,
                                                const std::vector<ident::ModeEstimate>& modes,
                                                const std::string& source) {
  const Eigen::Index n = masses.size();
  Require(
      static_cast<Eigen::Index>(modes.size()) == n,
      source + ": " + std::to_string(modes.size()) + " modes for " + std::to_string(n) + " masses");
  Eigen::VectorXd omega(n), zeta(n);
  Eigen::MatrixXd shapes(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& m = modes[static_cast<std::size_t>(i)];
    omega[i] = m.omega_rad_s;
    zeta[i] = m.zeta;
    if (n == 2 && std::isfinite(m.ratio)) {
      shapes.col(i) << m.ratio, 1.0;
    } else {
      Require(m.shape.size() == n, source + ": mode " + std::to_string(i + 1) +
                                       " needs a shape of " + std::to_string(n) +
                                       " entries (or a ratio for 2 masses)");
      shapes.col(i) = m.shape;
    }
  }
  return ident::UpdateStiffness(masses, omega, zeta, shapes);
}

namespace {

constexpr const char* kMassHelp =
    "Effective mass of one mass alone on its spring (1-DOF hammer test): fit |H| = 1/sqrt((k - m "
    "w^2)^2 + (c w)^2)\n"
    "to the coherence-weighted log receptance around the resonance (Levenberg-Marquardt), c "
    "started from the\n"
    "half-power damping and refined (--fixed-damping keeps it).";

struct MassArgs {
  std::string input;
  bool json = false;
  std::string output;
  std::string sensors;
  EstimationArgs est;
  ident::MassUpdateOptions options;
};

std::string MassText(const ident::MassUpdateResult& r,
                     const std::array<ident::Interval95, 3>& intervals) {
  std::ostringstream out;
  out << "effective mass " << r.mass_kg << " kg";
  if (r.nominal_kg > 0.0)
    out << " (nominal " << r.nominal_kg << " kg, " << r.change_percent << " %)";
  const ident::Interval95& m = intervals[0];
  const ident::Interval95& k = intervals[1];
  const ident::Interval95& c = intervals[2];
  out << "\nk " << r.k_n_per_m << " N/m" << (r.stiffness_fitted ? " (fitted)" : " (given)")
      << ", zeta " << r.zeta
      << (r.damping_fitted ? " (fitted; half-power " + std::to_string(r.zeta_half_power) + ")"
                           : " (half-power)")
      << ", c " << r.c_ns_per_m << " N*s/m, omega " << r.omega_rad_s << " rad/s\n"
      << "fit: " << numerics::TerminationName(r.summary.termination) << ", " << r.summary.iterations
      << " iterations, " << r.lines_fitted << " lines\n"
      << "95 % intervals: m " << ident::FormatInterval(m, r.mass_kg) << " kg, k "
      << ident::FormatInterval(k, r.k_n_per_m) << " N/m, c "
      << ident::FormatInterval(c, r.c_ns_per_m) << " N*s/m"
      << (m.Known() ? " (" + m.basis + ")" : "") << "\n";
  return out.str();
}

void Run(const MassArgs& a) {
  Require(a.est.kind == "receptance",
          "the mass update fits a receptance; leave --kind at its default");
  // Refused before the recording is read: the estimation's own messages would come first.
  if (!a.est.responses.empty()) {
    const std::size_t given = ParseColumnList(a.est.responses).size();
    Require(given == 1,
            "update mass: give exactly one response (got " + std::to_string(given) + ")");
  }
  std::vector<std::string> notes;
  const ident::Frf frf = LoadOrEstimate(a.input, a.est, notes);
  Require(frf.responses() == 1,
          "update mass: give exactly one response (got " + std::to_string(frf.responses()) + ")");
  const ident::MassUpdateResult r = ident::UpdateMass(frf, 0, a.options);
  if (!r.summary.Converged())
    throw NumericalError("mass update did not converge: " + r.summary.message);
  // The sensors' calibration in the intervals (--sensors): the load cell's and the response's.
  workflow::PositionCalibration cal;
  std::vector<std::string> warnings = r.warnings;
  if (!a.sensors.empty()) {
    // The columns the FRF names (a recording's, or an FRF file's sidecar's).
    const std::string force = frf.force_name.empty() ? a.est.force : frf.force_name;
    cal = workflow::CalibrationOfPositions(
              device::SensorsFromJson(ReadJsonFile(a.sensors), a.sensors),
              force.empty() ? "force" : force, {frf.response_names.front()}, warnings)
              .front();
  }
  if (a.json) {
    nlohmann::json j = MassUpdateJson(r, cal.relative_u, cal.sensors);
    j["notes"] = notes;
    EmitOutput(j.dump(2) + "\n", a.output);
  } else {
    EmitOutput(MassText(r, workflow::MassUpdateIntervals(r, cal.relative_u, cal.sensors)),
               a.output);
  }
  for (const auto& w : warnings) std::cerr << "vibid: warning: " << w << "\n";
}

constexpr const char* kStiffnessHelp =
    "Stiffness from modal tests (Eq. 7): K = M Phi Omega^2 Phi^T M with mass-normalised shapes; "
    "chain springs\n"
    "k2 = K22, k1 = K11 - K22, a least-squares chain fit and the off-diagonal mismatch; tests "
    "averaged,\n"
    "with 95 % intervals from the modes' intervals, the tests' scatter and --mass-ci95.";

struct StiffnessArgs {
  std::string masses;
  std::string mass_ci95;
  std::vector<std::string> modes;
  bool json = false;
  std::string output;
};

std::string StiffnessText(const ident::StiffnessAverage& avg, const ident::ChainUncertainty& u,
                          std::size_t tests) {
  std::ostringstream out;
  out << "springs (k_n = K_nn, k_i = K_ii - k_i+1):";
  for (Eigen::Index i = 0; i < avg.springs.size(); ++i)
    out << " k" << i + 1 << " = " << avg.springs[i];
  out << " N/m\ndampers (same convention):";
  for (Eigen::Index i = 0; i < avg.dampers.size(); ++i)
    out << " c" << i + 1 << " = " << avg.dampers[i];
  out << " N*s/m\n95 % intervals:";
  std::string basis;
  for (Eigen::Index i = 0; i < avg.springs.size(); ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const ident::Interval95 k = ident::IntervalOf(avg.springs[i], u.springs[ui]);
    const ident::Interval95 c = ident::IntervalOf(avg.dampers[i], u.dampers[ui]);
    out << (i ? "," : "") << " k" << i + 1 << " " << ident::FormatInterval(k, avg.springs[i])
        << ", c" << i + 1 << " " << ident::FormatInterval(c, avg.dampers[i]);
    if (basis.empty() && k.Known()) basis = k.basis;
  }
  if (!basis.empty()) out << "\n  from: " << basis;
  out << "\nleast-squares chain:";
  for (Eigen::Index i = 0; i < avg.springs_lsq.size(); ++i)
    out << " k" << i + 1 << " = " << avg.springs_lsq[i];
  out << " N/m\noff-diagonal mismatch " << avg.offdiag_mismatch_percent << " % over " << tests
      << " test(s)\n";
  return out.str();
}

void Run(const StiffnessArgs& a) {
  const std::vector<double> mv = ParsePositiveList(a.masses, "--masses");
  const Eigen::VectorXd masses =
      Eigen::Map<const Eigen::VectorXd>(mv.data(), static_cast<Eigen::Index>(mv.size()));
  std::vector<ident::StiffnessUpdateResult> tests;
  std::vector<std::vector<ident::ModeEstimate>> modes;
  for (const std::string& path : a.modes) {
    modes.push_back(ModesFromJson(ReadJsonFile(path), path));
    tests.push_back(StiffnessFromModes(masses, modes.back(), path));
  }
  const ident::StiffnessAverage avg = ident::AverageStiffness(tests);
  const ident::ChainUncertainty u =
      ident::StiffnessUncertainty(masses, MassUncertainties(a.mass_ci95, mv.size()), modes, tests);
  if (a.json) {
    nlohmann::json j = StiffnessJson(avg);
    // Per position: {"k_n_per_m_ci95": [lo, hi] or null, "..._basis" or "..._missing", and the
    // same for c_ns_per_m}.
    nlohmann::json cis = nlohmann::json::array();
    for (std::size_t i = 0; i < mv.size(); ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      nlohmann::json one;
      PutInterval(one, "k_n_per_m", ident::IntervalOf(avg.springs[ii], u.springs[i]));
      PutInterval(one, "c_ns_per_m", ident::IntervalOf(avg.dampers[ii], u.dampers[i]));
      cis.push_back(one);
    }
    j["intervals"] = cis;
    EmitOutput(j.dump(2) + "\n", a.output);
  } else {
    EmitOutput(StiffnessText(avg, u, tests.size()), a.output);
  }
}

void RegisterMassUpdate(CLI::App& update) {
  const auto [cmd, a] = AddCommand<MassArgs>(update, "mass", kMassHelp, Run);
  cmd->add_option("input", a->input, "Recording (REC.csv) or FRF file")->required();
  AddEstimationOptions(cmd, a->est, false, "receptance");
  cmd->add_option("--stiffness-n-per-m", a->options.k_n_per_m,
                  "Known spring stiffness (N/m); omitted: fitted too")
      ->check(PositiveNumber());
  cmd->add_option("--sensors", a->sensors,
                  "Sensors file whose sensitivities state their certificate's uncertainty: the "
                  "intervals carry the load cell's and the response's calibration part");
  cmd->add_option("--nominal-kg", a->options.nominal_kg, "Nominal mass (kg) for the % change")
      ->check(PositiveNumber());
  cmd->add_option("--band", a->options.band_fraction,
                  "Fitted band: omega within (1 +- band) omega_peak")
      ->capture_default_str();
  cmd->add_flag("--fixed-damping{false}", a->options.fit_damping,
                "Hold c at the half-power value instead of refining it in the fit");
  cmd->add_flag("--json", a->json, "JSON output");
  cmd->add_option("-o,--output", a->output, "Write the result here instead of stdout");
}

void RegisterStiffnessUpdate(CLI::App& update) {
  const auto [cmd, a] = AddCommand<StiffnessArgs>(update, "stiffness", kStiffnessHelp, Run);
  cmd->add_option("--masses", a->masses, "Masses m1,m2,... (kg), e.g. from `update mass`")
      ->required();
  cmd->add_option("--mass-ci95", a->mass_ci95,
                  "95 % half-widths of the masses (kg), e.g. from `update mass`; omitted: the\n"
                  "masses are taken as exact and the intervals hold the modes' share only");
  cmd->add_option("--modes", a->modes, "MODES.json from `vibid modes --json`, one per test")
      ->required();
  cmd->add_flag("--json", a->json, "JSON output");
  cmd->add_option("-o,--output", a->output, "Write the result here instead of stdout");
}

}  // namespace

void RegisterUpdate(CLI::App& app) {
  CLI::App* update =
      app.add_subcommand("update", "Update a model's masses or springs from test data");
  update->require_subcommand(1);
  RegisterMassUpdate(*update);
  RegisterStiffnessUpdate(*update);
}

}  // namespace vibid::cli
