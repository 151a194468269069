#include "vibid/workflow/sysid_run.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/option_text.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/model/transfer_function.hpp"
#include "vibid/numerics/polynomial.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/greybox.hpp"
#include "vibid/sysid/instrumental.hpp"
#include "vibid/sysid/pem.hpp"
#include "vibid/sysid/tfest.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::workflow {

sysid::IoData LoadIoData(const SysidRecord& args) {
  RecordingOptions ro;
  ro.fs_hz = args.fs_hz;
  const Recording rec = LoadRecording(args.path, ro);
  const ColumnSpec in = ParseColumnSpec(args.input);
  const ColumnSpec out = ParseColumnSpec(args.output);
  sysid::IoData data =
      sysid::MakeIoData(rec.Signal(in), rec.Signal(out), rec.dt_s(), in.name, out.name);
  Require(args.detrend == "none" || args.detrend == "mean" || args.detrend == "linear",
          "--detrend '" + args.detrend + "': none, mean or linear");
  Require(args.decimate >= 1 && args.decimate <= 1000, "--decimate must be 1..1000");
  const sysid::Trend trend = args.detrend == "mean"     ? sysid::Trend::kMean
                             : args.detrend == "linear" ? sysid::Trend::kLinear
                                                        : sysid::Trend::kNone;
  data = sysid::Detrend(data, trend).data;
  return sysid::Decimate(data, args.decimate);
}

sysid::IoData ApplyRange(const sysid::IoData& data, const std::string& range,
                         const std::string& option) {
  if (range.empty()) return data;
  try {
    const sysid::SampleRange r = sysid::ParseSampleRange(range, data.samples());
    return sysid::MakeIoData(data.u.segment(r.first, r.last - r.first),
                             data.y.segment(r.first, r.last - r.first), data.dt_s);
  } catch (const InputError& e) {
    throw InputError(option + ": " + e.what());
  }
}

nlohmann::json ResidualJson(const sysid::ResidualTests& t) {
  return {{"max_lag", t.max_lag},
          {"confidence", t.confidence},
          {"whiteness",
           {{"passed", t.white},
            {"ljung_box_q", t.ljung_box},
            {"threshold", t.ljung_box_threshold},
            {"bound", t.autocorrelation_bound},
            {"lags_outside", t.autocorrelation_outside},
            {"autocorrelation", ToStdVector(t.autocorrelation)}}},
          {"input_independence",
           {{"passed", t.independent},
            {"statistic", t.cross_correlation_statistic},
            {"threshold", t.cross_correlation_threshold},
            {"bound", t.cross_correlation_bound},
            {"lags_outside", t.cross_correlation_outside},
            {"cross_correlation", ToStdVector(t.cross_correlation)}}}};
}

std::vector<std::string> ResidualCautions(const sysid::ResidualTests& t) {
  std::vector<std::string> out;
  char text[700];
  if (!t.white) {
    std::snprintf(
        text, sizeof text,
        "the residuals are not white (Ljung-Box Q %.4g above %.4g, its %.0f %% "
        "threshold over %d lags; %d lags outside +-%.3g): the model leaves dynamics in "
        "them that it does not explain (dry friction, a nonlinearity, orders too low), so "
        "the fit overstates what it predicts and stds made for white residuals are too "
        "small",
        t.ljung_box, t.ljung_box_threshold, 100.0 * t.confidence, t.max_lag,
        t.autocorrelation_outside, t.autocorrelation_bound);
    out.emplace_back(text);
  }
  if (!t.independent) {
    std::snprintf(text, sizeof text,
                  "the residuals depend on the input (cross-correlation statistic %.4g above %.4g, "
                  "%d lags outside +-%.3g): part of the input-to-output path is missing from the "
                  "model; other orders, or a model with the friction, may hold it",
                  t.cross_correlation_statistic, t.cross_correlation_threshold,
                  t.cross_correlation_outside, t.cross_correlation_bound);
    out.emplace_back(text);
  }
  return out;
}

namespace {

// The cautions into the report's JSON (always there, empty when none), kept for the text's end.
void AddCautions(const std::vector<std::string>& cautions, nlohmann::json& j,
                 std::vector<std::string>& out) {
  out.insert(out.end(), cautions.begin(), cautions.end());
  j["cautions"] = out;
}

// The text's last lines: one CAUTION line each.
std::string CautionLines(const std::vector<std::string>& cautions) {
  std::string out;
  for (const std::string& c : cautions) out += "CAUTION: " + c + "\n";
  return out;
}

}  // namespace

std::optional<sysid::ResidualTests> TryResidualTests(const Eigen::VectorXd& residual,
                                                     const Eigen::VectorXd& input) {
  if (residual.size() <= 100 || residual.squaredNorm() == 0.0 || !residual.allFinite())
    return std::nullopt;
  return sysid::TestResiduals(residual, input, 25, 0.99);
}

std::vector<double> ToStdVector(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

Eigen::VectorXd JsonVector(const nlohmann::json& j, const std::string& key,
                           const std::string& source) {
  Require(j.contains(key) && j[key].is_array(), source + ": missing array '" + key + "'");
  std::vector<double> v;
  for (const auto& x : j[key]) {
    Require(x.is_number() && std::isfinite(x.get<double>()),
            source + ": '" + key + "' must hold finite numbers");
    v.push_back(x.get<double>());
  }
  Require(!v.empty(), source + ": '" + key + "' is empty");
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

nlohmann::json PolyModelJson(const sysid::PolyModel& m) {
  return {{"structure", sysid::StructureName(m.structure)},
          {"A", ToStdVector(m.a)},
          {"B", ToStdVector(m.b)},
          {"C", ToStdVector(m.c)},
          {"D", ToStdVector(m.d)},
          {"F", ToStdVector(m.f)},
          {"nk", m.orders.nk},
          {"dt_s", m.dt_s}};
}

sysid::PolyModel PolyModelFromJson(const nlohmann::json& j, const std::string& source) {
  // The keys `arx` and `pem` write: the polynomials are read, the rest reports the estimation.
  RequireKnownKeys(j,
                   {"structure",
                    "A",
                    "B",
                    "C",
                    "D",
                    "F",
                    "nk",
                    "dt_s",
                    "std",
                    "fit_kind",
                    "fit_percent",
                    "prediction_fit_percent",
                    "noise_variance",
                    "samples",
                    "fs_hz",
                    "residuals",
                    "validation",
                    "continuous",
                    "loss",
                    "order_selection",
                    "summary",
                    "initialization",
                    "cautions"},
                   "polynomial model file " + source);
  sysid::PolyModel m;
  m.a = JsonVector(j, "A", source);
  m.b = JsonVector(j, "B", source);
  auto optional_poly = [&](const char* key) {
    return j.contains(key) ? JsonVector(j, key, source) : Eigen::VectorXd(Eigen::VectorXd::Ones(1));
  };
  m.c = optional_poly("C");
  m.d = optional_poly("D");
  m.f = optional_poly("F");
  for (const auto* p : {&m.a, &m.c, &m.d, &m.f}) {
    Require((*p)[0] == 1.0, source + ": A, C, D and F must be monic (first coefficient 1)");
  }
  Require(j.contains("dt_s") && j["dt_s"].is_number() && j["dt_s"].get<double>() > 0.0,
          source + ": missing a positive 'dt_s' (sample period of the discrete model)");
  m.dt_s = j["dt_s"].get<double>();
  int nk = 0;
  while (nk < m.b.size() && m.b[nk] == 0.0) ++nk;
  m.orders = sysid::PolyOrders{static_cast<int>(m.a.size() - 1),
                               static_cast<int>(std::max<Eigen::Index>(m.b.size() - nk, 1)),
                               static_cast<int>(m.c.size() - 1),
                               static_cast<int>(m.d.size() - 1),
                               static_cast<int>(m.f.size() - 1),
                               nk};
  if (j.contains("structure") && j["structure"].is_string())
    m.structure = sysid::ParseStructure(j["structure"]);
  return m;
}

std::string FormatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string FormatVector(const Eigen::VectorXd& v) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i ? ", " : "") + FormatNumber(v[i]);
  return s + "]";
}

void CheckSolver(const numerics::SolverSummary& s, const std::string& what) {
  if (s.termination == numerics::TerminationType::kNumericalFailure) {
    throw NumericalError(what + " did not produce a model: " + s.message);
  }
}

namespace {

/// Standard deviations laid out like the polynomials (0 for fixed leading ones and delay zeros).
nlohmann::json StdJson(const sysid::PolyModel& m) {
  const Eigen::VectorXd sd = m.covariance.size() > 0
                                 ? Eigen::VectorXd(m.covariance.diagonal().cwiseSqrt())
                                 : Eigen::VectorXd::Zero(m.orders.Parameters());
  auto place = [](Eigen::Index length, Eigen::Index offset, const Eigen::VectorXd& values) {
    std::vector<double> v(static_cast<std::size_t>(length), 0.0);
    for (Eigen::Index i = 0; i < values.size(); ++i)
      v[static_cast<std::size_t>(offset + i)] = values[i];
    return v;
  };
  const auto& o = m.orders;
  Eigen::Index i = 0;
  nlohmann::json j;
  j["A"] = place(m.a.size(), 1, sd.segment(i, o.na));
  i += o.na;
  j["B"] = place(m.b.size(), o.nk, sd.segment(i, o.nb));
  i += o.nb;
  j["C"] = place(m.c.size(), 1, sd.segment(i, o.nc));
  i += o.nc;
  j["D"] = place(m.d.size(), 1, sd.segment(i, o.nd));
  i += o.nd;
  j["F"] = place(m.f.size(), 1, sd.segment(i, o.nf));
  return j;
}

/// Fits, residual tests, validation and the d2c form, shared by arx and pem.
nlohmann::json ModelReport(const sysid::PolyModel& m, const sysid::IoData& est,
                           const sysid::IoData& all, const PolyRequest& a, std::ostringstream& text,
                           std::vector<std::string>& cautions) {
  nlohmann::json j = PolyModelJson(m);
  j["std"] = StdJson(m);
  j["fit_kind"] = "simulation, zero initial conditions, estimation samples";
  j["fit_percent"] = sysid::FitPercent(est.y, sysid::SimulatePoly(m, est.u));
  j["prediction_fit_percent"] = sysid::FitPercent(est.y, sysid::PredictKStep(m, est, 1));
  j["noise_variance"] = m.noise_variance;
  j["samples"] = est.samples();
  j["fs_hz"] = 1.0 / m.dt_s;
  const Eigen::VectorXd e = sysid::PredictionErrors(m, est);
  const std::optional<sysid::ResidualTests> tests = TryResidualTests(e, est.u);
  if (tests) j["residuals"] = ResidualJson(*tests);
  text << "A = " << FormatVector(m.a) << "\nB = " << FormatVector(m.b) << "\n";
  if (m.c.size() > 1) text << "C = " << FormatVector(m.c) << "\n";
  if (m.d.size() > 1) text << "D = " << FormatVector(m.d) << "\n";
  if (m.f.size() > 1) text << "F = " << FormatVector(m.f) << "\n";
  text << "fit " << FormatNumber(j["fit_percent"]) << " % (simulation), "
       << FormatNumber(j["prediction_fit_percent"]) << " % (1-step prediction) on " << est.samples()
       << " samples\n";
  if (!a.validate_range.empty()) {
    const sysid::IoData val = ApplyRange(all, a.validate_range, "--validate-range");
    j["validation"] = {
        {"fit_percent", sysid::FitPercent(val.y, sysid::SimulatePoly(m, val.u))},
        {"prediction_fit_percent", sysid::FitPercent(val.y, sysid::PredictKStep(m, val, 1))},
        {"samples", val.samples()}};
    text << "validation fit " << FormatNumber(j["validation"]["fit_percent"])
         << " % (simulation)\n";
  }
  if (a.d2c) {
    Require(m.orders.nk <= 1,
            "--d2c: nk = " + std::to_string(m.orders.nk) +
                " is a delay of more than one sample, which has no continuous-time TF");
    const Eigen::VectorXd den = numerics::MultiplyPolynomials(m.a, m.f);
    Eigen::VectorXd num = m.b;
    Require(num.size() <= den.size(),
            "--d2c: B longer than A·F: the model is not causal in continuous time");
    const sysid::TransferFunction tf = sysid::Normalized(sysid::D2cZoh(num, den, m.dt_s));
    j["continuous"] = {{"num", ToStdVector(tf.num)}, {"den", ToStdVector(tf.den)}};
    text << "continuous (d2c, ZOH): num = " << FormatVector(tf.num)
         << ", den = " << FormatVector(tf.den) << "\n";
  }
  AddCautions(tests ? ResidualCautions(*tests) : std::vector<std::string>{}, j, cautions);
  return j;
}

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
sysid::TransferFunction ContinuousTf(const nlohmann::json& model, const CompareRequest& a,
                                     nlohmann::json& j) {
  if (model.contains("num") || model.contains("den")) {
    // The keys `tfest` and `greybox cart` write: num and den are read, the rest reports the fit.
    RequireKnownKeys(model,
                     {"num",
                      "den",
                      "std",
                      "fit_percent",
                      "fit_kind",
                      "ic",
                      "ic_num",
                      "noise_variance",
                      "samples",
                      "fs_hz",
                      "initialization",
                      "summary",
                      "residuals",
                      "validation",
                      "model",
                      "carts",
                      "input_kind",
                      "units",
                      "parameters",
                      "std_basis",
                      "cautions"},
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
                                   const CompareRequest& a) {
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
                                   int horizon, const CompareRequest& a) {
  const sysid::PolyModel m = PolyModelFromJson(model, a.model);
  Require(a.method == "exact", "--method euler|rk4 applies to continuous-time TFs only");
  Require(a.ic == "zero", "--ic estimate applies to continuous-time TFs only");
  Require(std::abs(m.dt_s - data.dt_s) <= 1e-9 * m.dt_s,
          "the model's sample period " + FormatNumber(m.dt_s) + " s differs from the record's " +
              FormatNumber(data.dt_s) + " s");
  return horizon > 0 ? sysid::PredictKStep(m, data, horizon) : sysid::SimulatePoly(m, data.u);
}

}  // namespace

/// "na=2,nb=2,nk=1" or MATLAB's order vectors: arx [na nb nk], armax [na nb nc nk], oe [nb nf nk],
/// bj [nb nc nd nf nk] written "2,2,1".
sysid::PolyOrders ParseOrders(const std::string& text, sysid::Structure s) {
  sysid::PolyOrders o;
  o.nb = 0;
  const std::vector<std::string> items = SplitOptionList(text, TrailingEmpty::kDrop);
  Require(!items.empty(), "--orders is empty");
  auto integer = [&](const std::string& v) {
    const std::optional<long long> n = ParseInteger(v);
    Require(n && *n >= 0 && *n <= std::numeric_limits<int>::max(),
            "--orders: '" + v + "' is not an integer >= 0");
    return static_cast<int>(*n);
  };
  const bool named = items[0].find('=') != std::string::npos;
  if (named) {
    o.nk = 1;
    for (const auto& item : items) {
      const auto eq = item.find('=');
      Require(eq != std::string::npos, "--orders: '" + item + "' must be NAME=N");
      const std::string key = item.substr(0, eq);
      const int v = integer(item.substr(eq + 1));
      if (key == "na")
        o.na = v;
      else if (key == "nb")
        o.nb = v;
      else if (key == "nc")
        o.nc = v;
      else if (key == "nd")
        o.nd = v;
      else if (key == "nf")
        o.nf = v;
      else if (key == "nk")
        o.nk = v;
      else
        throw InputError("--orders: unknown order '" + key + "' (na, nb, nc, nd, nf, nk)");
    }
    return o;
  }
  std::vector<int*> slots;
  switch (s) {
    case sysid::Structure::kArx: slots = {&o.na, &o.nb, &o.nk}; break;
    case sysid::Structure::kArmax: slots = {&o.na, &o.nb, &o.nc, &o.nk}; break;
    case sysid::Structure::kOe: slots = {&o.nb, &o.nf, &o.nk}; break;
    case sysid::Structure::kBj: slots = {&o.nb, &o.nc, &o.nd, &o.nf, &o.nk}; break;
  }
  Require(items.size() == slots.size(), std::string("--orders for ") + sysid::StructureName(s) +
                                            " takes " + std::to_string(slots.size()) +
                                            " numbers (" +
                                            (s == sysid::Structure::kArx     ? "na,nb,nk"
                                             : s == sysid::Structure::kArmax ? "na,nb,nc,nk"
                                             : s == sysid::Structure::kOe    ? "nb,nf,nk"
                                                                             : "nb,nc,nd,nf,nk") +
                                            ") or NAME=N pairs");
  for (std::size_t i = 0; i < items.size(); ++i) *slots[i] = integer(items[i]);
  return o;
}

SysidReport RunArx(const ArxRequest& a) {
  Require(a.select.empty() || a.select == "aic" || a.select == "fpe",
          "--select '" + a.select + "': aic or fpe");
  Require(a.max_order >= 1 && a.max_order <= 200, "--max-order must be 1..200");
  const sysid::IoData all = LoadIoData(a.poly.record);
  const sysid::IoData est = ApplyRange(all, a.poly.estimate_range, "--estimate-range");
  std::ostringstream text;
  nlohmann::json selection;
  sysid::PolyOrders o{a.na, a.nb, 0, 0, 0, a.nk};
  if (!a.select.empty()) {
    Require(a.na < 0 && a.nb < 0, "give either --select or --na/--nb, not both");
    const auto crit = a.select == "aic" ? sysid::OrderCriterion::kAic : sysid::OrderCriterion::kFpe;
    const sysid::OrderSelection sel = sysid::SelectArxOrder(est, 1, a.max_order, a.nk, crit);
    for (const auto& c : sel.candidates) {
      selection.push_back(
          {{"na", c.orders.na}, {"nb", c.orders.nb}, {"loss", c.loss}, {a.select, c.criterion}});
      text << "na=nb=" << c.orders.na << ": loss " << FormatNumber(c.loss) << ", " << a.select
           << " " << FormatNumber(c.criterion) << "\n";
    }
    o = sel.candidates[sel.best].orders;
    text << "selected na=nb=" << o.na << "\n";
  } else {
    Require(a.na >= 0 && a.nb >= 1, "arx needs --na and --nb (or --select aic|fpe)");
  }
  const sysid::ArxResult r = sysid::EstimateArx(est, o);
  std::vector<std::string> cautions;
  nlohmann::json j = ModelReport(r.model, est, all, a.poly, text, cautions);
  j["loss"] = r.loss;
  if (!selection.is_null()) j["order_selection"] = selection;
  return {j, text.str() + CautionLines(cautions), cautions};
}

SysidReport RunPem(const PemRequest& a) {
  Require(a.max_iterations >= 1 && a.max_iterations <= 100000,
          "--max-iterations must be 1..100000");
  const sysid::Structure s = sysid::ParseStructure(a.structure);
  const sysid::PolyOrders o = ParseOrders(a.orders, s);
  numerics::SolverOptions so;
  so.max_iterations = a.max_iterations;
  const sysid::IoData all = LoadIoData(a.poly.record);
  const sysid::IoData est = ApplyRange(all, a.poly.estimate_range, "--estimate-range");
  const sysid::PemResult r = sysid::EstimatePem(est, s, o, so);
  if (r.summary.termination == numerics::TerminationType::kNumericalFailure) {
    throw NumericalError("pem did not produce a model: " + r.summary.message);
  }
  std::ostringstream text;
  std::vector<std::string> cautions;
  nlohmann::json j = ModelReport(r.model, est, all, a.poly, text, cautions);
  j["summary"] = SolverSummaryJson(r.summary);
  j["initialization"] = r.initialization;
  text << "search: " << numerics::TerminationName(r.summary.termination) << " after "
       << r.summary.iterations << " iterations (" << r.initialization << " start), cost "
       << FormatNumber(r.summary.initial_cost) << " -> " << FormatNumber(r.summary.final_cost)
       << "\n";
  return {j, text.str() + CautionLines(cautions), cautions};
}

SysidReport RunTfest(const TfestRequest& a) {
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
  const std::optional<sysid::ResidualTests> tests = TryResidualTests(residual, est.u);
  if (tests) j["residuals"] = ResidualJson(*tests);
  std::vector<std::string> cautions;
  AddCautions(tests ? ResidualCautions(*tests) : std::vector<std::string>{}, j, cautions);
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
  return {j, text.str() + CautionLines(cautions), cautions};
}

namespace {

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

}  // namespace

SysidReport RunGreybox(const GreyboxRequest& a) {
  Require(a.input_kind == "force" || a.input_kind == "position",
          "--input-kind '" + a.input_kind + "': force or position");
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
  const bool widened = r.std_basis != "white residuals";
  for (const auto& p : r.parameters) {
    params[p.name] = {
        {"value", p.value}, {"std", p.std}, {"std_white", p.std_white}, {"fixed", p.fixed}};
    text << p.name << " = " << FormatNumber(p.value)
         << (p.fixed ? " (fixed)" : " +- " + FormatNumber(p.std));
    if (!p.fixed && widened)
      text << " (white residuals would say +- " << FormatNumber(p.std_white) << ")";
    text << "\n";
  }
  text << "fit " << FormatNumber(r.fit_percent) << " % (simulation) on " << est.samples()
       << " samples; search " << numerics::TerminationName(r.summary.termination) << " after "
       << r.summary.iterations << " iterations\n";
  if (widened) text << "stds: " << r.std_basis << ", as the residual tests below fail\n";
  nlohmann::json j{{"model", "cart"},
                   {"carts", a.carts},
                   {"input_kind", a.input_kind},
                   {"units", "M kg, B and Bi N*s/m, k N/m (each of the springs to either side)"},
                   {"parameters", params},
                   {"std_basis", r.std_basis},
                   {"num", ToStdVector(r.tf.num)},
                   {"den", ToStdVector(r.tf.den)},
                   {"fit_percent", r.fit_percent},
                   {"ic", a.ic},
                   {"initialization", r.initialization},
                   {"summary", SolverSummaryJson(r.summary)}};
  if (r.residual_tests) j["residuals"] = ResidualJson(*r.residual_tests);
  std::vector<std::string> cautions;
  AddCautions(r.residual_tests ? ResidualCautions(*r.residual_tests) : std::vector<std::string>{},
              j, cautions);
  return {j, text.str() + CautionLines(cautions), cautions};
}

CompareReport RunCompare(const CompareRequest& a) {
  Require(a.method == "exact" || a.method == "euler" || a.method == "rk4",
          "--method '" + a.method + "': exact, euler or rk4");
  Require(a.ic == "zero" || a.ic == "estimate", "--ic '" + a.ic + "': zero or estimate");
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
  std::ostringstream text;
  text << "fit " << FormatNumber(fit) << " % ("
       << (horizon > 0 ? std::to_string(horizon) + "-step prediction" : "simulation") << ", "
       << a.method << ", ic " << a.ic << ") on " << data.samples() << " samples\n";
  CompareReport r;
  r.json = j;
  r.text = text.str();
  r.t_s = Eigen::VectorXd::LinSpaced(data.samples(), 0.0, static_cast<double>(data.samples() - 1)) *
          data.dt_s;
  r.y = data.y;
  r.y_model = y_hat;
  return r;
}

}  // namespace vibid::workflow
