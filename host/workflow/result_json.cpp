#include "vibid/workflow/result_json.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>

#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/numerics/least_squares.hpp"

namespace vibid::workflow {

namespace {

std::vector<double> ToStd(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

nlohmann::json MatrixJson(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) rows.push_back(ToStd(m.row(i).transpose()));
  return rows;
}

}  // namespace

nlohmann::json ModesToJson(const std::vector<ident::ModeEstimate>& modes) {
  nlohmann::json arr = nlohmann::json::array();
  for (const auto& m : modes) {
    nlohmann::json j;
    j["omega_rad_s"] = m.omega_rad_s;
    j["freq_hz"] = m.freq_hz;
    j["zeta"] = m.zeta;
    j["ratio"] = std::isfinite(m.ratio) ? nlohmann::json(m.ratio) : nlohmann::json(nullptr);
    j["shape"] = std::vector<double>(m.shape.data(), m.shape.data() + m.shape.size());
    if (m.shape_ratio.size() == m.shape.size() && m.shape.size() > 0) {
      nlohmann::json r = nlohmann::json::array();
      for (Eigen::Index k = 0; k < m.shape_ratio.size(); ++k)
        r.push_back(std::isfinite(m.shape_ratio[k]) ? nlohmann::json(m.shape_ratio[k])
                                                    : nlohmann::json(nullptr));
      j["shape_ratio"] = r;
    }
    j["unreliable"] = m.unreliable;
    if (!m.caution.empty()) j["caution"] = m.caution;
    if (m.amplitude.checked) {
      const ident::AmplitudeDamping& a = m.amplitude;
      const auto ci = [](const std::array<double, 2>& c) {
        return std::isfinite(c[0]) && std::isfinite(c[1]) && c[1] > c[0]
                   ? nlohmann::json{c[0], c[1]}
                   : nlohmann::json(nullptr);
      };
      j["zeta_amplitude"] = {{"hits", a.hits},
                             {"zeta_early", a.zeta_early},
                             {"zeta_late", a.zeta_late},
                             {"zeta_viscous", a.zeta_viscous},
                             {"zeta_viscous_ci95", ci(a.zeta_viscous_ci95)},
                             {"modal_friction_n", a.modal_friction_n},
                             {"modal_friction_ci95_n", ci(a.modal_friction_ci95)},
                             {"friction_per_mass_n", std::isfinite(a.friction_per_mass_n)
                                                         ? nlohmann::json(a.friction_per_mass_n)
                                                         : nlohmann::json(nullptr)},
                             {"amplitude_dependent", a.amplitude_dependent},
                             {"stops_early", a.stops_early},
                             {"friction_hint", a.friction_hint},
                             {"friction_rate_t", a.friction_rate_t},
                             {"zeta_friction_bias", a.zeta_friction_bias}};
      if (a.stops_early) {
        j["zeta_amplitude"]["stop_s"] = a.stop_s;
        j["zeta_amplitude"]["expected_stop_s"] = a.expected_stop_s;
      }
    }
    if (m.HasAnyInterval()) {
      const auto pair = [](const std::array<double, 2>& ci) {
        return std::isfinite(ci[0]) && std::isfinite(ci[1]) && ci[1] > ci[0]
                   ? nlohmann::json{ci[0], ci[1]}
                   : nlohmann::json(nullptr);
      };
      j["ci95"] = {{"omega_rad_s", pair(m.omega_ci95_rad_s)},
                   {"zeta", pair(m.zeta_ci95)},
                   {"ratio", pair(m.ratio_ci95)}};
      if (!m.shape_ratio_ci95.empty()) {
        nlohmann::json r = nlohmann::json::array();
        for (const auto& ci : m.shape_ratio_ci95) r.push_back(pair(ci));
        j["ci95"]["shape_ratio"] = r;
      }
    }
    arr.push_back(j);
  }
  return nlohmann::json{{"modes", arr}};
}

std::vector<ident::ModeEstimate> ModesFromJson(const nlohmann::json& json,
                                               const std::string& source) {
  Require(json.is_object() && json.contains("modes") && json["modes"].is_array(),
          source + ": expected an object with a \"modes\" array");
  // What `modes --json` writes around the modes; the reader takes the modes alone.
  RequireKnownKeys(json,
                   {"modes", "method", "responses", "warnings", "notes", "stabilization", "summary",
                    "fit_band_hz", "rms_relative_error", "peaks_without_mode_hz"},
                   "modes file " + source);
  std::vector<ident::ModeEstimate> modes;
  std::size_t i = 0;
  for (const auto& m : json["modes"]) {
    ++i;
    const std::string where = source + ": mode " + std::to_string(i);
    Require(m.is_object() && m.contains("omega_rad_s") && m["omega_rad_s"].is_number(),
            where + ": omega_rad_s missing or not a number");
    RequireKnownKeys(m,
                     {"omega_rad_s", "freq_hz", "zeta", "ratio", "shape", "ci95", "shape_ratio",
                      "unreliable", "caution", "zeta_amplitude"},
                     "modes file " + source + " mode " + std::to_string(i));
    ident::ModeEstimate e;
    e.omega_rad_s = m["omega_rad_s"].get<double>();
    Require(std::isfinite(e.omega_rad_s) && e.omega_rad_s > 0.0,
            where + ": omega_rad_s must be > 0");
    e.freq_hz = e.omega_rad_s / (2.0 * std::numbers::pi);
    e.zeta = m.contains("zeta") && m["zeta"].is_number() ? m["zeta"].get<double>() : 0.0;
    e.ratio = m.contains("ratio") && m["ratio"].is_number()
                  ? m["ratio"].get<double>()
                  : std::numeric_limits<double>::quiet_NaN();
    if (m.contains("ci95")) {
      Require(m["ci95"].is_object(), where + ": ci95 must be an object");
      RequireKnownKeys(m["ci95"], {"omega_rad_s", "zeta", "ratio", "shape_ratio"},
                       "modes file " + source + " mode " + std::to_string(i) + " ci95");
      const auto read = [&](const char* key, std::array<double, 2>& ci) {
        if (!m["ci95"].contains(key) || m["ci95"][key].is_null()) return;
        const nlohmann::json& v = m["ci95"][key];
        Require(v.is_array() && v.size() == 2 && v[0].is_number() && v[1].is_number() &&
                    v[0].get<double>() < v[1].get<double>(),
                where + ": ci95." + key + " must be [lo, hi] with lo < hi (null: no interval)");
        ci = {v[0].get<double>(), v[1].get<double>()};
      };
      read("omega_rad_s", e.omega_ci95_rad_s);
      read("zeta", e.zeta_ci95);
      read("ratio", e.ratio_ci95);
    }
    if (m.contains("shape")) {
      Require(m["shape"].is_array(), where + ": shape must be an array");
      std::vector<double> s;
      for (const auto& v : m["shape"]) {
        Require(v.is_number(), where + ": shape entries must be numbers");
        s.push_back(v.get<double>());
      }
      e.shape = Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size()));
    }
    if (m.contains("unreliable") && m["unreliable"].is_boolean())
      e.unreliable = m["unreliable"].get<bool>();
    if (m.contains("caution") && m["caution"].is_string())
      e.caution = m["caution"].get<std::string>();
    modes.push_back(e);
  }
  Require(!modes.empty(), source + ": the \"modes\" array is empty");
  return modes;
}

nlohmann::json DiagramToJson(const ident::StabilizationDiagram& d) {
  nlohmann::json poles = nlohmann::json::array();
  for (const auto& p : d.poles) {
    poles.push_back({{"order", p.order},
                     {"freq_hz", p.freq_hz},
                     {"zeta", p.zeta},
                     {"stable_freq", p.stable_freq},
                     {"stable_damping", p.stable_damping},
                     {"stable_shape", p.stable_shape},
                     {"cluster", p.cluster}});
  }
  nlohmann::json selected = nlohmann::json::array();
  for (const auto& s : d.selected) {
    selected.push_back({{"freq_hz", s.freq_hz},
                        {"omega_rad_s", s.omega_rad_s},
                        {"zeta", s.zeta},
                        {"orders", s.orders},
                        {"freq_spread", s.freq_spread},
                        {"zeta_spread", s.zeta_spread}});
  }
  return {{"method", ident::PoleMethodName(d.method)},
          {"band_hz", {d.freq_min_hz, d.freq_max_hz}},
          {"orders", d.orders},
          {"poles", poles},
          {"selected", selected}};
}

nlohmann::json ModeIdentificationJson(const ident::ModeIdentification& r, const std::string& method,
                                      const std::vector<std::string>& responses,
                                      const std::vector<std::string>& notes) {
  nlohmann::json j = ModesToJson(r.modes);
  j["method"] = method;
  j["responses"] = responses;
  j["warnings"] = r.warnings;
  j["notes"] = notes;
  j["peaks_without_mode_hz"] = r.peaks_without_mode_hz;
  if (r.has_diagram) j["stabilization"] = DiagramToJson(r.diagram);
  if (r.fitted) {
    j["summary"] = SolverSummaryJson(r.fit.summary);
    j["fit_band_hz"] = {r.fit.freq_min_hz, r.fit.freq_max_hz};
    j["rms_relative_error"] = r.fit.rms_relative_error;
  }
  return j;
}

std::string ModesTable(const std::vector<ident::ModeEstimate>& modes) {
  std::ostringstream out;
  bool intervals = false;
  bool two = true;  // every mode has two responses: the a1/a2 column
  for (const auto& m : modes) {
    intervals = intervals || m.HasAnyInterval();
    two = two && m.shape.size() == 2;
  }
  bool single = true;  // one response: its shape entry alone
  for (const auto& m : modes) single = single && m.shape.size() == 1;
  if (single) {
    out << "mode   freq_hz      omega_rad_s"
        << (intervals ? " (95 %)     zeta (95 %)             " : "  zeta       ") << "shape\n";
  } else if (intervals) {
    out << "mode   freq_hz      omega_rad_s (95 %)     zeta (95 %)             "
        << (two ? "ratio a1/a2 (95 %)   shape" : "shape / driving point (95 %)") << "\n";
  } else {
    out << "mode   freq_hz      omega_rad_s  zeta       "
        << (two ? "ratio a1/a2  shape" : "shape / driving point") << "\n";
  }
  const auto pm = [](double value, const std::array<double, 2>& ci, const char* format) {
    char text[96];
    std::snprintf(text, sizeof text, format, value);
    // The library gives an interval only with a positive width; one it could not estimate is
    // said as such, never shown as +- 0.
    if (std::isfinite(ci[0]) && std::isfinite(ci[1]) && ci[1] > ci[0]) {
      char hw[32];
      std::snprintf(hw, sizeof hw, "%.2g", 0.5 * (ci[1] - ci[0]));
      return std::string(text) + " +- " + hw;
    }
    return std::string(text) + (std::isfinite(value) ? " +- n/a" : "");
  };
  // More than two responses: phi_j / phi_p for every response (1 at the driving point), each with
  // its interval.
  const auto ratios = [&](const ident::ModeEstimate& m) {
    std::string text;
    const bool have = m.shape_ratio.size() == m.shape.size();
    for (Eigen::Index j = 0; j < m.shape.size(); ++j) {
      const std::size_t jj = static_cast<std::size_t>(j);
      std::string item;
      if (!have) {
        char v[32];
        std::snprintf(v, sizeof v, "%.5g", m.shape[j]);
        item = v;
      } else if (m.shape_ratio[j] == 1.0 && jj < m.shape_ratio_ci95.size() &&
                 !std::isfinite(m.shape_ratio_ci95[jj][0])) {
        item = "1";
      } else {
        item =
            intervals && jj < m.shape_ratio_ci95.size()
                ? pm(m.shape_ratio[j], m.shape_ratio_ci95[jj], "%.5g")
                : pm(m.shape_ratio[j],
                     {ident::ModeEstimate::kNoInterval, ident::ModeEstimate::kNoInterval}, "%.5g");
        if (!intervals) item = item.substr(0, item.find(" +-"));
      }
      text += (j ? ", " : "") + item;
    }
    return text;
  };
  std::vector<std::string> cautions;
  for (std::size_t i = 0; i < modes.size(); ++i) {
    const auto& m = modes[i];
    char line[256];
    if (intervals) {
      std::snprintf(line, sizeof line, "%-6zu %-12.5g %-22s %-23s", i + 1, m.freq_hz,
                    pm(m.omega_rad_s, m.omega_ci95_rad_s, "%.6g").c_str(),
                    pm(m.zeta, m.zeta_ci95, "%.4g").c_str());
    } else {
      std::snprintf(line, sizeof line, "%-6zu %-12.5g %-12.5g %-10.4g", i + 1, m.freq_hz,
                    m.omega_rad_s, m.zeta);
    }
    out << line;
    if (single) {
      std::snprintf(line, sizeof line, " %.5g", m.shape[0]);
      out << line;
    } else if (two) {
      if (intervals) {
        std::snprintf(line, sizeof line, " %-20s", pm(m.ratio, m.ratio_ci95, "%.5g").c_str());
      } else {
        std::snprintf(line, sizeof line, " %-12.5g", m.ratio);
      }
      out << line;
      for (Eigen::Index j = 0; j < m.shape.size(); ++j) {
        std::snprintf(line, sizeof line, " %.5g", m.shape[j]);
        out << line;
      }
    } else {
      out << " " << ratios(m);
    }
    if (m.unreliable)
      out << "  UNRELIABLE (" << cautions.size() + 1 << ")";
    else if (!m.caution.empty())
      out << "  (" << cautions.size() + 1 << ")";
    if (!m.caution.empty()) cautions.push_back(m.caution);
    out << "\n";
  }
  for (std::size_t k = 0; k < cautions.size(); ++k)
    out << "(" << k + 1 << ") " << cautions[k] << "\n";
  return out.str();
}

std::string ModeIdentificationText(const ident::ModeIdentification& r) {
  std::ostringstream out;
  out << ModesTable(r.modes);
  if (r.has_diagram) {
    out << "stabilization diagram: " << ident::PoleMethodName(r.diagram.method) << ", orders "
        << r.diagram.orders.front() << ".." << r.diagram.orders.back() << ", band "
        << r.diagram.freq_min_hz << ".." << r.diagram.freq_max_hz << " Hz, "
        << r.diagram.poles.size() << " poles, " << r.diagram.selected.size()
        << " chosen; residue fit rms relative misfit " << r.fit.rms_relative_error << "\n";
  } else if (r.fitted) {
    out << "curve fit: " << numerics::TerminationName(r.fit.summary.termination) << ", "
        << r.fit.summary.iterations << " iterations, cost " << r.fit.summary.initial_cost << " -> "
        << r.fit.summary.final_cost << ", rms relative misfit " << r.fit.rms_relative_error << "\n";
  }
  return out.str();
}

void PutInterval(nlohmann::json& j, const std::string& key, const ident::Interval95& ci) {
  if (ci.Known()) {
    j[key + "_ci95"] = {ci.lo, ci.hi};
    j[key + "_ci95_basis"] = ci.basis;
    // Its two parts (half-widths) when the sensors' calibration is in it.
    if (ci.HasCalibration()) {
      j[key + "_ci95_statistical_half_width"] = ci.statistical_half_width;
      j[key + "_ci95_calibration_half_width"] = ci.calibration_half_width;
    }
  } else {
    j[key + "_ci95"] = nullptr;
    j[key + "_ci95_missing"] = ci.missing;
  }
}

std::array<ident::Interval95, 3> MassUpdateIntervals(const ident::MassUpdateResult& r,
                                                     double calibration_u,
                                                     const std::string& sensors) {
  std::array<ident::Interval95, 3> out = {ident::IntervalOf(r.mass_kg, r.mass_u),
                                          ident::IntervalOf(r.k_n_per_m, r.k_u),
                                          ident::IntervalOf(r.c_ns_per_m, r.c_u)};
  const double values[] = {r.mass_kg, r.k_n_per_m, r.c_ns_per_m};
  for (std::size_t i = 0; i < 3; ++i)
    ident::AddCalibration(out[i], values[i], calibration_u, sensors);
  return out;
}

nlohmann::json MassUpdateJson(const ident::MassUpdateResult& r, double calibration_u,
                              const std::string& sensors) {
  nlohmann::json j = {{"mass_kg", r.mass_kg},
                      {"nominal_kg", r.nominal_kg},
                      {"change_percent", r.change_percent},
                      {"zeta", r.zeta},
                      {"zeta_half_power", r.zeta_half_power},
                      {"damping_fitted", r.damping_fitted},
                      {"k_n_per_m", r.k_n_per_m},
                      {"stiffness_fitted", r.stiffness_fitted},
                      {"c_ns_per_m", r.c_ns_per_m},
                      {"omega_rad_s", r.omega_rad_s},
                      {"lines_fitted", r.lines_fitted},
                      {"warnings", r.warnings},
                      {"summary", SolverSummaryJson(r.summary)}};
  const std::array<ident::Interval95, 3> ci = MassUpdateIntervals(r, calibration_u, sensors);
  PutInterval(j, "mass_kg", ci[0]);
  PutInterval(j, "k_n_per_m", ci[1]);
  PutInterval(j, "c_ns_per_m", ci[2]);
  return j;
}

nlohmann::json StiffnessJson(const ident::StiffnessAverage& avg) {
  nlohmann::json tests = nlohmann::json::array();
  for (const auto& t : avg.tests) {
    tests.push_back({{"springs", ToStd(t.springs)},
                     {"K", MatrixJson(t.k_matrix)},
                     {"springs_lsq", ToStd(t.springs_lsq)},
                     {"dampers", ToStd(t.dampers)},
                     {"offdiag_mismatch_percent", t.offdiag_mismatch_percent}});
  }
  return {{"springs", ToStd(avg.springs)},
          {"K", MatrixJson(avg.k_matrix)},
          {"springs_lsq", ToStd(avg.springs_lsq)},
          {"offdiag_mismatch_percent", avg.offdiag_mismatch_percent},
          {"spread", ToStd(avg.spread)},
          {"dampers", ToStd(avg.dampers)},
          {"tests", tests}};
}

}  // namespace vibid::workflow
