#include "vibid/workflow/decay_run.hpp"

#include <cmath>
#include <sstream>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/numerics/least_squares.hpp"

namespace vibid::workflow {
namespace {

struct DecaySet {
  std::vector<ident::DecayResult> results;
  double omega_d = 0.0, zeta = 0.0, omega_n = 0.0;
  double omega_d_std = 0.0, zeta_std = 0.0;
};

DecaySet AnalyzeAll(const std::vector<std::string>& paths, const DecayRequest& r) {
  DecaySet s;
  for (const std::string& p : paths) {
    RecordingOptions ro;
    if (r.fs_hz > 0.0) ro.fs_hz = r.fs_hz;
    const ColumnSpec spec = ParseColumnSpec(r.position);
    ro.channels = {spec.name};
    const Recording rec = LoadRecording(p, ro);
    const Eigen::VectorXd x = rec.Signal(spec) * r.scale;
    try {
      s.results.push_back(ident::AnalyzeDecay(x, rec.fs_hz, r.options));
    } catch (const InputError& e) {
      throw InputError(p + ": " + e.what());
    }
  }
  const auto n = static_cast<double>(s.results.size());
  for (const auto& res : s.results) {
    s.omega_d += res.omega_d_rad_s / n;
    s.zeta += res.zeta / n;
    s.omega_n += res.omega_n_rad_s / n;
  }
  if (s.results.size() > 1) {
    for (const auto& res : s.results) {
      s.omega_d_std += (res.omega_d_rad_s - s.omega_d) * (res.omega_d_rad_s - s.omega_d) / (n - 1);
      s.zeta_std += (res.zeta - s.zeta) * (res.zeta - s.zeta) / (n - 1);
    }
    s.omega_d_std = std::sqrt(s.omega_d_std);
    s.zeta_std = std::sqrt(s.zeta_std);
  }
  return s;
}

nlohmann::json FrictionJson(const ident::DecayFriction& f) {
  if (!f.checked) return {{"checked", false}, {"note", f.note}};
  const auto number = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
  };
  return {{"checked", true},
          {"detected", f.detected},
          {"half_cycles", f.half_cycles},
          {"zeta_first", f.zeta_first},
          {"zeta_last", f.zeta_last},
          {"zeta_viscous", number(f.zeta_viscous)},
          {"drop_per_half_cycle", f.drop_per_half_cycle},
          {"drop_ci95", f.drop_ci95},
          {"friction_over_k", f.friction_over_k},
          {"omega_first_rad_s", f.omega_first_rad_s},
          {"omega_last_rad_s", f.omega_last_rad_s}};
}

nlohmann::json SetJson(const DecaySet& s, const std::vector<std::string>& paths) {
  nlohmann::json recs = nlohmann::json::array();
  for (std::size_t i = 0; i < s.results.size(); ++i) {
    const auto& r = s.results[i];
    recs.push_back({{"file", paths[i]},
                    {"omega_d_rad_s", r.omega_d_rad_s},
                    {"zeta", r.zeta},
                    {"omega_n_rad_s", r.omega_n_rad_s},
                    {"t_release_s", r.t_release_s},
                    {"fit_samples", r.fit_samples},
                    {"amplitude", r.amplitude},
                    {"offset", r.offset},
                    {"rms_residual", r.rms_residual},
                    {"zeta_log_decrement", r.zeta_log_decrement},
                    {"cycles", r.cycles},
                    {"termination", numerics::TerminationName(r.summary.termination)},
                    {"friction", FrictionJson(r.friction)},
                    {"cautions", r.cautions}});
  }
  nlohmann::json cautions = nlohmann::json::array();
  for (std::size_t i = 0; i < s.results.size(); ++i) {
    for (const std::string& c : s.results[i].cautions) cautions.push_back(paths[i] + ": " + c);
  }
  return {{"omega_d_rad_s", s.omega_d},   {"zeta", s.zeta},         {"omega_n_rad_s", s.omega_n},
          {"omega_d_std", s.omega_d_std}, {"zeta_std", s.zeta_std}, {"records", recs},
          {"cautions", cautions}};
}

}  // namespace

nlohmann::json RunDecay(const DecayRequest& r) {
  // An average of nothing would read as omega 0: refused.
  Require(!r.recordings.empty(), "no recordings: give at least one pull-and-release record");
  Require(r.loaded.empty() || r.added_kg > 0.0, "--loaded needs --added-kg");
  Require(r.added_kg == 0.0 || !r.loaded.empty(), "--added-kg needs --loaded records");
  const DecaySet base = AnalyzeAll(r.recordings, r);
  nlohmann::json j = SetJson(base, r.recordings);
  nlohmann::json cautions = j["cautions"];
  if (!r.loaded.empty()) {
    const DecaySet loaded = AnalyzeAll(r.loaded, r);
    const ident::AddedMassSolution s =
        ident::SolveAddedMass(base.omega_n, loaded.omega_n, r.added_kg);
    j["loaded"] = SetJson(loaded, r.loaded);
    j["added_kg"] = r.added_kg;
    j["k_n_per_m"] = s.k_n_per_m;
    j["base_mass_kg"] = s.base_mass_kg;
    for (const auto& c : j["loaded"]["cautions"]) cautions.push_back(c);
  }
  // Every record's cautions, the loaded ones' too: a caller tests this one list.
  j["cautions"] = cautions;
  return j;
}

std::string DecayText(const nlohmann::json& j) {
  std::ostringstream text;
  text << "omega_d " << j["omega_d_rad_s"].get<double>() << " rad/s, zeta "
       << j["zeta"].get<double>() << ", omega_n " << j["omega_n_rad_s"].get<double>() << " rad/s";
  if (j["records"].size() > 1)
    text << " (mean of " << j["records"].size() << "; sd " << j["omega_d_std"].get<double>() << ", "
         << j["zeta_std"].get<double>() << ")";
  text << "\n";
  if (j.contains("loaded")) {
    const nlohmann::json& l = j["loaded"];
    text << "loaded: omega_d " << l["omega_d_rad_s"].get<double>() << " rad/s, zeta "
         << l["zeta"].get<double>() << ", omega_n " << l["omega_n_rad_s"].get<double>()
         << " rad/s\nk " << j["k_n_per_m"].get<double>() << " N/m, base mass "
         << j["base_mass_kg"].get<double>() << " kg\n";
  }
  for (const auto& c : j["cautions"]) text << "CAUTION: " << c.get<std::string>() << "\n";
  return text.str();
}

}  // namespace vibid::workflow
