// vibid tfest, vibid compare, vibid greybox cart: continuous-time models.
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/common/option_text.hpp"
#include "common/solver_json.hpp"
#include "sysid/sysid_cli.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/model/transfer_function.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/greybox.hpp"
#include "vibid/sysid/tfest.hpp"

namespace vibid::cli {

namespace {

void CheckSolver(const numerics::SolverSummary& s, const std::string& what) {
  if (s.termination == numerics::TerminationType::kNumericalFailure) {
    throw NumericalError(what + " did not produce a model: " + s.message);
  }
}

constexpr const char* kTfestHelp =
    "Continuous-time transfer function num(s)/den(s) (SRIVC start, output-error refinement)";

struct TfestArgs {
  RecordArgs record;
  int np = 2;
  int nz = 0;
  std::string ic = "zero";
  std::string estimate_range;
  std::string validate_range;
  int max_iterations = 200;
  bool json = false;
  std::string out;
};

void Run(const TfestArgs& a) {
  sysid::TfestOptions o;
  o.np = a.np;
  o.nz = a.nz;
  o.ic = sysid::ParseInitialCondition(a.ic);
  o.solver.max_iterations = a.max_iterations;
  o.Validate();
  const sysid::IoData all = LoadIoData(a.record);
  const sysid::IoData est = ApplyRange(all, a.estimate_range, "--estimate-range");
  const sysid::TfestResult r = sysid::EstimateTf(est, o);
  CheckSolver(r.summary, "tfest");
  nlohmann::json j{
      {"num", ToStdVector(r.tf.num)},
      {"den", ToStdVector(r.tf.den)},
      {"std", {{"num", ToStdVector(r.num_std)}, {"den", ToStdVector(r.den_std)}}},
      {"fit_percent", r.fit_percent},
      {"fit_kind", "simulation on the estimation samples, with the initial conditions below"},
      {"ic", sysid::InitialConditionName(o.ic)},
      {"ic_num", ToStdVector(r.ic_num)},
      {"noise_variance", r.noise_variance},
      {"samples", est.samples()},
      {"fs_hz", 1.0 / est.dt_s},
      {"initialization", r.initialization},
      {"summary", SolverSummaryJson(r.summary)}};
  const Eigen::VectorXd residual = est.y - sysid::SimulateWithIc(r.tf, r.ic_num, est.u, est.dt_s);
  if (const auto t = TryResidualTests(residual, est.u)) j["residuals"] = ResidualJson(*t);
  std::ostringstream text;
  text << "num = " << FormatVector(r.tf.num) << "\nden = " << FormatVector(r.tf.den) << "\nfit "
       << FormatNumber(r.fit_percent) << " % (simulation, ic " << a.ic << ") on " << est.samples()
       << " samples\n"
       << "search: " << numerics::TerminationName(r.summary.termination) << " after "
       << r.summary.iterations << " iterations, start " << r.initialization << "\n";
  if (!a.validate_range.empty()) {
    const sysid::IoData val = ApplyRange(all, a.validate_range, "--validate-range");
    const Eigen::VectorXd ic_val = o.ic == sysid::InitialCondition::kEstimate
                                       ? sysid::FitInitialCondition(r.tf, val)
                                       : Eigen::VectorXd(Eigen::VectorXd::Zero(o.np));
    const double fit =
        sysid::FitPercent(val.y, sysid::SimulateWithIc(r.tf, ic_val, val.u, val.dt_s));
    j["validation"] = {{"fit_percent", fit}, {"samples", val.samples()}};
    text << "validation fit " << FormatNumber(fit) << " %\n";
  }
  Emit(j, text.str(), a.json, a.out);
}

constexpr const char* kCompareHelp =
    "Fit of a model's simulated (or k-step predicted) output to a recording: "
    "100(1-|y-yhat|/|y-mean(y)|) %";

struct CompareArgs {
  RecordArgs record;
  std::string model;
  std::string horizon = "inf";
  std::string method = "exact";
  int substeps = 1;
  std::string ic = "zero";
  std::string range;
  std::string write_sim;
  int input_dof = 1;
  int output_dof = 1;
  bool json = false;
};

/// --horizon: 0 for inf (simulation), else the prediction horizon in samples.
int ParseHorizon(const std::string& text) {
  if (text == "inf") return 0;
  const std::optional<long long> horizon = ParseInteger(text);
  Require(horizon && *horizon >= 1 && *horizon <= std::numeric_limits<int>::max(),
          "--horizon must be inf or an integer >= 1");
  return static_cast<int>(*horizon);
}

/// The continuous TF of `model`: a num/den file as it is, a model file's receptance between the
/// chosen DOFs. Says which in j["model_kind"].
sysid::TransferFunction ContinuousTf(const nlohmann::json& model, const CompareArgs& a,
                                     nlohmann::json& j) {
  if (model.contains("num") || model.contains("den")) {
    // The keys `tfest` and `greybox cart` write: num and den are read, the rest reports the fit.
    RequireKnownKeys(
        model,
        {"num", "den", "std", "fit_percent", "fit_kind", "ic", "ic_num", "noise_variance",
         "samples", "fs_hz", "initialization", "summary", "residuals", "validation", "model",
         "carts", "input_kind", "units", "parameters"},
        "transfer-function file " + a.model);
    j["model_kind"] = "continuous";
    return sysid::Normalized(sysid::TransferFunction{JsonVector(model, "num", a.model),
                                                     JsonVector(model, "den", a.model)});
  }
  const model::Model m = model::ModelFromJson(model, a.model);
  Require(a.input_dof <= m.dofs() && a.output_dof <= m.dofs(),
          "--input-dof/--output-dof: the model has " + std::to_string(m.dofs()) + " DOFs");
  const model::TransferFunction mtf = model::ModelTransferFunction(
      m, a.input_dof - 1, a.output_dof - 1, model::FrfKind::kReceptance);
  j["model_kind"] = "model file (receptance DOF " + std::to_string(a.input_dof) + " -> " +
                    std::to_string(a.output_dof) + ")";
  return sysid::Normalized(sysid::TransferFunction{mtf.num, mtf.den});
}

Eigen::VectorXd SimulateContinuous(const sysid::TransferFunction& tf, const sysid::IoData& data,
                                   const CompareArgs& a) {
  Eigen::VectorXd ic_num = Eigen::VectorXd::Zero(tf.Order());
  if (a.ic == "estimate") {
    Require(a.method == "exact", "--ic estimate works with --method exact");
    ic_num = sysid::FitInitialCondition(tf, data);
  }
  if (a.method == "exact") return sysid::SimulateWithIc(tf, ic_num, data.u, data.dt_s);
  if (a.method == "euler") return sysid::SimulateEuler(tf, data.u, data.dt_s, a.substeps);
  return sysid::SimulateRk4(tf, data.u, data.dt_s, a.substeps);
}

Eigen::VectorXd SimulatePolynomial(const nlohmann::json& model, const sysid::IoData& data,
                                   int horizon, const CompareArgs& a) {
  const sysid::PolyModel m = PolyModelFromJson(model, a.model);
  Require(a.method == "exact", "--method euler|rk4 applies to continuous-time TFs only");
  Require(a.ic == "zero", "--ic estimate applies to continuous-time TFs only");
  Require(std::abs(m.dt_s - data.dt_s) <= 1e-9 * m.dt_s,
          "the model's sample period " + FormatNumber(m.dt_s) + " s differs from the record's " +
              FormatNumber(data.dt_s) + " s");
  return horizon > 0 ? sysid::PredictKStep(m, data, horizon) : sysid::SimulatePoly(m, data.u);
}

void Run(const CompareArgs& a) {
  const int horizon = ParseHorizon(a.horizon);
  const nlohmann::json model = ReadJsonFile(a.model);
  const sysid::IoData data = ApplyRange(LoadIoData(a.record), a.range, "--range");
  Eigen::VectorXd y_hat;
  nlohmann::json j;
  std::string note;
  if (!(model.contains("A") && model.contains("B"))) {
    y_hat = SimulateContinuous(ContinuousTf(model, a, j), data, a);
    if (horizon > 0)
      note = "output-error model (noise model 1): every prediction horizon equals simulation";
  } else {
    y_hat = SimulatePolynomial(model, data, horizon, a);
    j["model_kind"] = "polynomial";
  }
  Require(y_hat.allFinite(),
          "the model's output diverges on this record (unstable model or method)");
  const double fit = sysid::FitPercent(data.y, y_hat);
  j["fit_percent"] = fit;
  j["horizon"] = horizon > 0 ? nlohmann::json(horizon) : nlohmann::json("inf");
  j["method"] = a.method;
  j["ic"] = a.ic;
  j["samples"] = data.samples();
  if (!note.empty()) j["note"] = note;
  if (const auto t = TryResidualTests(data.y - y_hat, data.u)) j["residuals"] = ResidualJson(*t);
  if (!a.write_sim.empty()) {
    const Eigen::VectorXd t =
        Eigen::VectorXd::LinSpaced(data.samples(), 0.0, static_cast<double>(data.samples() - 1)) *
        data.dt_s;
    WriteFileAtomic(a.write_sim, FormatCsv({"t_s", "y", "y_model"}, {t, data.y, y_hat}));
  }
  std::ostringstream text;
  text << "fit " << FormatNumber(fit) << " % ("
       << (horizon > 0 ? std::to_string(horizon) + "-step prediction" : "simulation") << ", "
       << a.method << ", ic " << a.ic << ") on " << data.samples() << " samples\n";
  Emit(j, text.str(), a.json, "");
}

constexpr const char* kGreyboxHelp =
    "Cart track (methods §10): M, B, k (and Bi) of one cart or M1, M2, B1, B2, k (and Bi) of two";

struct GreyboxArgs {
  RecordArgs record;
  int carts = 1;
  std::string input_kind = "force";
  std::string fix;
  std::string ic = "zero";
  std::string estimate_range;
  bool json = false;
  std::string out;
};

/// --fix NAME=VALUE,...: the parameters held at a value.
void ParseFixed(const std::string& text, sysid::GreyboxOptions& o) {
  for (const std::string& item : SplitOptionList(text, TrailingEmpty::kDrop)) {
    const auto eq = item.find('=');
    Require(eq != std::string::npos && eq > 0, "--fix: '" + item + "' must be NAME=VALUE");
    const std::string value = item.substr(eq + 1);
    double v = 0.0;
    Require(ParseNumber(value, v) == NumberText::kOk, "--fix: '" + value + "' is not a number");
    o.fixed[item.substr(0, eq)] = v;
  }
}

void Run(const GreyboxArgs& a) {
  sysid::GreyboxOptions o;
  o.config.carts = a.carts;
  o.config.input = a.input_kind == "force" ? sysid::CartInput::kForce : sysid::CartInput::kPosition;
  o.ic = sysid::ParseInitialCondition(a.ic);
  ParseFixed(a.fix, o);
  o.Validate();
  const sysid::IoData est = ApplyRange(LoadIoData(a.record), a.estimate_range, "--estimate-range");
  const sysid::GreyboxResult r = sysid::EstimateCart(est, o);
  CheckSolver(r.summary, "greybox");
  nlohmann::json params = nlohmann::json::object();
  std::ostringstream text;
  for (const auto& p : r.parameters) {
    params[p.name] = {{"value", p.value}, {"std", p.std}, {"fixed", p.fixed}};
    text << p.name << " = " << FormatNumber(p.value)
         << (p.fixed ? " (fixed)" : " +- " + FormatNumber(p.std)) << "\n";
  }
  text << "fit " << FormatNumber(r.fit_percent) << " % (simulation) on " << est.samples()
       << " samples; search " << numerics::TerminationName(r.summary.termination) << " after "
       << r.summary.iterations << " iterations\n";
  nlohmann::json j{{"model", "cart"},
                   {"carts", a.carts},
                   {"input_kind", a.input_kind},
                   {"units", "M kg, B and Bi N*s/m, k N/m (each of the springs to either side)"},
                   {"parameters", params},
                   {"num", ToStdVector(r.tf.num)},
                   {"den", ToStdVector(r.tf.den)},
                   {"fit_percent", r.fit_percent},
                   {"ic", a.ic},
                   {"initialization", r.initialization},
                   {"summary", SolverSummaryJson(r.summary)}};
  Emit(j, text.str(), a.json, a.out);
}

}  // namespace

void RegisterTfestCommand(CLI::App& app) {
  const auto [cmd, a] = AddCommand<TfestArgs>(app, "tfest", kTfestHelp, Run);
  AddRecordOptions(*cmd, a->record);
  cmd->add_option("--np", a->np, "Number of poles")->required()->check(CLI::Range(1, 20));
  cmd->add_option("--nz", a->nz, "Number of zeros (< np)")->check(CLI::Range(0, 19));
  cmd->add_option("--ic", a->ic, "Initial conditions: zero (record starts at rest) | estimate")
      ->check(CLI::IsMember({"zero", "estimate"}));
  cmd->add_option("--estimate-range", a->estimate_range,
                  "Samples FIRST:LAST (LAST excluded) used for estimation");
  cmd->add_option("--validate-range", a->validate_range, "Samples FIRST:LAST for a validation fit");
  cmd->add_option("--max-iterations", a->max_iterations,
                  "Iteration limit of the output-error search")
      ->check(CLI::Range(1, 100000));
  cmd->add_flag("--json", a->json, "Print the result as JSON");
  cmd->add_option("-o,--out", a->out, "Write the TF (JSON, readable by compare) to this file");
}

void RegisterCompareCommand(CLI::App& app) {
  const auto [cmd, a] = AddCommand<CompareArgs>(app, "compare", kCompareHelp, Run);
  AddRecordOptions(*cmd, a->record);
  cmd->add_option("--model", a->model,
                  "TF.json (num/den, as tfest and greybox write), a polynomial model (arx/pem -o), "
                  "or a model file "
                  "(M/C/K or topology; the input column is then a force in N, the output a "
                  "displacement in m)")
      ->required();
  cmd->add_option("--input-dof", a->input_dof, "Model file: DOF the input force acts on (from 1)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--output-dof", a->output_dof,
                  "Model file: DOF whose displacement is the output (from 1)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--horizon", a->horizon, "inf (simulation) or K >= 1 (K-step-ahead prediction)");
  cmd->add_option("--method", a->method, "Simulation of a continuous TF: exact (ZOH) | euler | rk4")
      ->check(CLI::IsMember({"exact", "euler", "rk4"}));
  cmd->add_option("--substeps", a->substeps, "Integration steps per sample for euler/rk4")
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--ic", a->ic,
                  "Initial conditions of a continuous TF: zero | estimate (least squares)")
      ->check(CLI::IsMember({"zero", "estimate"}));
  cmd->add_option("--range", a->range, "Samples FIRST:LAST (LAST excluded) to compare on");
  cmd->add_option("--write-sim", a->write_sim, "Write t_s, measured and model output to this CSV");
  cmd->add_flag("--json", a->json, "Print the result as JSON");
}

void RegisterGreyboxCommand(CLI::App& app) {
  auto* group = app.add_subcommand(
      "greybox", "Physical parameters by output error on a first-principle model");
  group->require_subcommand(1);
  const auto [cmd, a] = AddCommand<GreyboxArgs>(*group, "cart", kGreyboxHelp, Run);
  AddRecordOptions(*cmd, a->record);
  cmd->add_option("--carts", a->carts, "1 (cart 2 pinned) or 2")->check(CLI::IsMember({1, 2}));
  cmd->add_option("--input-kind", a->input_kind,
                  "force (N on cart 1) | position (Xi through the first spring, m)")
      ->check(CLI::IsMember({"force", "position"}));
  cmd->add_option("--fix", a->fix, "Parameters held fixed, e.g. M=0.57,k=15 (SI units)");
  cmd->add_option("--ic", a->ic, "Initial conditions: zero | estimate")
      ->check(CLI::IsMember({"zero", "estimate"}));
  cmd->add_option("--estimate-range", a->estimate_range,
                  "Samples FIRST:LAST (LAST excluded) used for estimation");
  cmd->add_flag("--json", a->json, "Print the result as JSON");
  cmd->add_option("-o,--out", a->out,
                  "Write the result (JSON, with num/den readable by compare) to this file");
}

}  // namespace vibid::cli
