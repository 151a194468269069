#include "sysid/sysid_cli.hpp"

#include <cmath>
#include <cstdio>

#include "cli_support.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"

namespace vibid::cli {

void AddRecordOptions(CLI::App& cmd, RecordArgs& args) {
  cmd.add_option("recording", args.path, "Recording (CSV with a header; t_s column or --fs-hz)")
      ->required();
  cmd.add_option("--input", args.input,
                 "Input column, e.g. V_volt or I_amp*-178.57 (NAME, NAME:UNIT, NAME*FACTOR)")
      ->required();
  cmd.add_option("--output", args.output, "Output column, e.g. X_encoder_counts*1.7857e-5")
      ->required();
  cmd.add_option("--fs-hz", args.fs_hz, "Sample rate, Hz, for records without a t_s column")
      ->check(PositiveNumber());
  cmd.add_option("--detrend", args.detrend, "Remove none|mean|linear trend from input and output")
      ->check(CLI::IsMember({"none", "mean", "linear"}));
  cmd.add_option("--decimate", args.decimate,
                 "Keep every N-th sample after an anti-alias FIR low-pass")
      ->check(CLI::Range(1, 1000));
}

sysid::IoData LoadIoData(const RecordArgs& args) {
  RecordingOptions ro;
  ro.fs_hz = args.fs_hz;
  const Recording rec = LoadRecording(args.path, ro);
  const ColumnSpec in = ParseColumnSpec(args.input);
  const ColumnSpec out = ParseColumnSpec(args.output);
  sysid::IoData data =
      sysid::MakeIoData(rec.Signal(in), rec.Signal(out), rec.dt_s(), in.name, out.name);
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
                    "initialization"},
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

void Emit(const nlohmann::json& j, const std::string& text, bool json,
          const std::string& out_path) {
  if (!out_path.empty()) EmitOutput(j.dump(2) + "\n", out_path);
  EmitOutput(json ? j.dump(2) + "\n" : text, "");
}

}  // namespace vibid::cli
