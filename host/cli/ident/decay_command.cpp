// `vibid decay`: free-decay analysis of pull-and-release records.
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "ident_commands.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/decay.hpp"

namespace vibid::cli {

namespace {

struct DecaySet {
  std::vector<ident::DecayResult> results;
  double omega_d = 0.0, zeta = 0.0, omega_n = 0.0;
  double omega_d_std = 0.0, zeta_std = 0.0;
};

DecaySet AnalyzeAll(const std::vector<std::string>& paths, const std::string& position,
                    double scale, double fs_hz, const ident::DecayOptions& options) {
  DecaySet s;
  for (const std::string& p : paths) {
    RecordingOptions ro;
    if (fs_hz > 0.0) ro.fs_hz = fs_hz;
    const ColumnSpec spec = ParseColumnSpec(position);
    ro.channels = {spec.name};
    const Recording rec = LoadRecording(p, ro);
    const Eigen::VectorXd x = rec.Signal(spec) * scale;
    try {
      s.results.push_back(ident::AnalyzeDecay(x, rec.fs_hz, options));
    } catch (const InputError& e) {
      throw InputError(p + ": " + e.what());
    }
  }
  const auto n = static_cast<double>(s.results.size());
  for (const auto& r : s.results) {
    s.omega_d += r.omega_d_rad_s / n;
    s.zeta += r.zeta / n;
    s.omega_n += r.omega_n_rad_s / n;
  }
  if (s.results.size() > 1) {
    for (const auto& r : s.results) {
      s.omega_d_std += (r.omega_d_rad_s - s.omega_d) * (r.omega_d_rad_s - s.omega_d) / (n - 1);
      s.zeta_std += (r.zeta - s.zeta) * (r.zeta - s.zeta) / (n - 1);
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

constexpr const char* kDecayHelp =
    "Free decay after a pull and release (no force channel): finds the release, fits x = x0 + A "
    "exp(-sigma t)\n"
    "cos(omega_d t + phi) over the first cycles, gives omega_d, zeta, omega_n (repeats averaged). "
    "With --loaded\n"
    "records of the same spring carrying --added-kg more, solves k and the base mass.";

struct DecayArgs {
  std::vector<std::string> inputs;
  std::vector<std::string> loaded;
  std::string position;
  double scale = 1.0;
  double fs_hz = 0.0;
  double added_kg = 0.0;
  ident::DecayOptions options{.end_fraction = 0.1, .cycles = 3};
  bool json = false;
  std::string output;
};

void Run(const DecayArgs& a) {
  Require(a.loaded.empty() || a.added_kg > 0.0, "--loaded needs --added-kg");
  Require(a.added_kg == 0.0 || !a.loaded.empty(), "--added-kg needs --loaded records");
  const DecaySet base = AnalyzeAll(a.inputs, a.position, a.scale, a.fs_hz, a.options);
  nlohmann::json j = SetJson(base, a.inputs);
  std::ostringstream text;
  text << "omega_d " << base.omega_d << " rad/s, zeta " << base.zeta << ", omega_n " << base.omega_n
       << " rad/s";
  if (base.results.size() > 1)
    text << " (mean of " << base.results.size() << "; sd " << base.omega_d_std << ", "
         << base.zeta_std << ")";
  text << "\n";
  if (!a.loaded.empty()) {
    const DecaySet loaded = AnalyzeAll(a.loaded, a.position, a.scale, a.fs_hz, a.options);
    const ident::AddedMassSolution s =
        ident::SolveAddedMass(base.omega_n, loaded.omega_n, a.added_kg);
    j["loaded"] = SetJson(loaded, a.loaded);
    j["added_kg"] = a.added_kg;
    j["k_n_per_m"] = s.k_n_per_m;
    j["base_mass_kg"] = s.base_mass_kg;
    text << "loaded: omega_d " << loaded.omega_d << " rad/s, zeta " << loaded.zeta << ", omega_n "
         << loaded.omega_n << " rad/s\nk " << s.k_n_per_m << " N/m, base mass " << s.base_mass_kg
         << " kg\n";
  }
  EmitOutput(a.json ? j.dump(2) + "\n" : text.str(), a.output);
}

}  // namespace

void RegisterDecay(CLI::App& app) {
  const auto [cmd, a] = AddCommand<DecayArgs>(app, "decay", kDecayHelp, Run);
  cmd->add_option("recordings", a->inputs, "Record(s) of the base configuration, REC.csv ...")
      ->required();
  cmd->add_option("--position", a->position, "Position column, NAME[:UNIT|*FACTOR] (e.g. X_cm:cm)")
      ->required();
  cmd->add_option("--scale", a->scale,
                  "Extra factor applied to the position (e.g. counts to metres)")
      ->check(PositiveNumber());
  cmd->add_option("--fs-hz", a->fs_hz, "Sample rate (Hz) when the file has no t_s column")
      ->check(PositiveNumber());
  cmd->add_option(
         "--cycles", a->options.cycles,
         "Cycles after the release in the fit (0: until the envelope falls below --end-fraction); "
         "friction\n"
         "makes damping grow as the amplitude falls, so the first cycles are the comparable ones")
      ->capture_default_str();
  cmd->add_option("--end-fraction", a->options.end_fraction,
                  "With --cycles 0: stop where the envelope falls below this fraction")
      ->capture_default_str();
  cmd->add_option("--loaded", a->loaded, "Record(s) with the added mass, for k and the base mass");
  cmd->add_option("--added-kg", a->added_kg, "Mass added in the --loaded records (kg)")
      ->check(PositiveNumber());
  cmd->add_flag("--json", a->json, "JSON output");
  cmd->add_option("-o,--output", a->output, "Write the result here instead of stdout");
}

}  // namespace vibid::cli
