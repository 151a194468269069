// vibid arx, vibid pem: discrete-time polynomial models.
#include <limits>
#include <optional>
#include <sstream>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/common/option_text.hpp"
#include "common/solver_json.hpp"
#include "sysid/sysid_cli.hpp"
#include "vibid/common/error.hpp"
#include "vibid/sysid/continuous.hpp"
#include "vibid/sysid/pem.hpp"
#include "vibid/numerics/polynomial.hpp"

namespace vibid::cli {

namespace {

struct PolyArgs {
  RecordArgs record;
  std::string estimate_range;
  std::string validate_range;
  bool json = false;
  bool d2c = false;
  std::string out;
};

void AddPolyOptions(CLI::App& cmd, PolyArgs& a) {
  AddRecordOptions(cmd, a.record);
  cmd.add_option("--estimate-range", a.estimate_range,
                 "Samples FIRST:LAST (LAST excluded) used for estimation");
  cmd.add_option("--validate-range", a.validate_range,
                 "Samples FIRST:LAST for a validation fit (simulation)");
  cmd.add_flag("--d2c", a.d2c,
               "Also give the continuous-time equivalent (ZOH inverse, needs nk <= 1)");
  cmd.add_flag("--json", a.json, "Print the result as JSON");
  cmd.add_option("-o,--out", a.out, "Write the model (JSON) to this file");
}

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
                           const sysid::IoData& all, const PolyArgs& a, std::ostringstream& text) {
  nlohmann::json j = PolyModelJson(m);
  j["std"] = StdJson(m);
  j["fit_kind"] = "simulation, zero initial conditions, estimation samples";
  j["fit_percent"] = sysid::FitPercent(est.y, sysid::SimulatePoly(m, est.u));
  j["prediction_fit_percent"] = sysid::FitPercent(est.y, sysid::PredictKStep(m, est, 1));
  j["noise_variance"] = m.noise_variance;
  j["samples"] = est.samples();
  j["fs_hz"] = 1.0 / m.dt_s;
  const Eigen::VectorXd e = sysid::PredictionErrors(m, est);
  if (const auto t = TryResidualTests(e, est.u)) j["residuals"] = ResidualJson(*t);
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
  return j;
}

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

constexpr const char* kArxHelp =
    "ARX model A(q)y = B(q)u + e by least squares (QR); coefficients in q^-1";

struct ArxArgs {
  PolyArgs poly;
  int na = -1;
  int nb = -1;
  int nk = 1;
  std::string select;
  int max_order = 10;
};

void Run(const ArxArgs& a) {
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
  nlohmann::json j = ModelReport(r.model, est, all, a.poly, text);
  j["loss"] = r.loss;
  if (!selection.is_null()) j["order_selection"] = selection;
  Emit(j, text.str(), a.poly.json, a.poly.out);
}

constexpr const char* kPemHelp =
    "Prediction-error model (arx, armax, oe, bj) by Levenberg-Marquardt";

struct PemArgs {
  PolyArgs poly;
  std::string structure;
  std::string orders;
  int max_iterations = 200;
};

void Run(const PemArgs& a) {
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
  nlohmann::json j = ModelReport(r.model, est, all, a.poly, text);
  j["summary"] = SolverSummaryJson(r.summary);
  j["initialization"] = r.initialization;
  text << "search: " << numerics::TerminationName(r.summary.termination) << " after "
       << r.summary.iterations << " iterations (" << r.initialization << " start), cost "
       << FormatNumber(r.summary.initial_cost) << " -> " << FormatNumber(r.summary.final_cost)
       << "\n";
  Emit(j, text.str(), a.poly.json, a.poly.out);
}

}  // namespace

void RegisterArxCommand(CLI::App& app) {
  const auto [cmd, a] = AddCommand<ArxArgs>(app, "arx", kArxHelp, Run);
  AddPolyOptions(*cmd, a->poly);
  cmd->add_option("--na", a->na, "Order of A")->check(CLI::NonNegativeNumber);
  cmd->add_option("--nb", a->nb, "Number of B coefficients")->check(CLI::PositiveNumber);
  cmd->add_option("--nk", a->nk, "Input delay in samples (MATLAB convention; default 1)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--select", a->select,
                  "Choose na = nb by aic|fpe over 1..--max-order instead of --na/--nb")
      ->check(CLI::IsMember({"aic", "fpe"}));
  cmd->add_option("--max-order", a->max_order, "Largest order tried by --select")
      ->check(CLI::Range(1, 200));
}

void RegisterPemCommand(CLI::App& app) {
  const auto [cmd, a] = AddCommand<PemArgs>(app, "pem", kPemHelp, Run);
  AddPolyOptions(*cmd, a->poly);
  cmd->add_option("--structure", a->structure, "arx | armax | oe | bj")
      ->required()
      ->check(CLI::IsMember({"arx", "armax", "oe", "bj"}));
  cmd->add_option("--orders", a->orders,
                  "Orders as NAME=N pairs (na,nb,nc,nd,nf,nk; nk defaults to 1) or MATLAB's "
                  "vector: arx na,nb,nk; "
                  "armax na,nb,nc,nk; oe nb,nf,nk; bj nb,nc,nd,nf,nk")
      ->required();
  cmd->add_option("--max-iterations", a->max_iterations, "Iteration limit of the search")
      ->check(CLI::Range(1, 100000));
}

}  // namespace vibid::cli
