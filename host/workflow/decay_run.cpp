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
                    {"termination", numerics::TerminationName(r.summary.termination)}});
  }
  return {{"omega_d_rad_s", s.omega_d},   {"zeta", s.zeta},         {"omega_n_rad_s", s.omega_n},
          {"omega_d_std", s.omega_d_std}, {"zeta_std", s.zeta_std}, {"records", recs}};
}

}  // namespace

nlohmann::json RunDecay(const DecayRequest& r) {
  // An average of nothing would read as omega 0: refused.
  Require(!r.recordings.empty(), "no recordings: give at least one pull-and-release record");
  Require(r.loaded.empty() || r.added_kg > 0.0, "--loaded needs --added-kg");
  Require(r.added_kg == 0.0 || !r.loaded.empty(), "--added-kg needs --loaded records");
  const DecaySet base = AnalyzeAll(r.recordings, r);
  nlohmann::json j = SetJson(base, r.recordings);
  if (!r.loaded.empty()) {
    const DecaySet loaded = AnalyzeAll(r.loaded, r);
    const ident::AddedMassSolution s =
        ident::SolveAddedMass(base.omega_n, loaded.omega_n, r.added_kg);
    j["loaded"] = SetJson(loaded, r.loaded);
    j["added_kg"] = r.added_kg;
    j["k_n_per_m"] = s.k_n_per_m;
    j["base_mass_kg"] = s.base_mass_kg;
  }
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
  return text.str();
}

}  // namespace vibid::workflow
