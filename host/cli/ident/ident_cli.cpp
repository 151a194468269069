#include "ident_cli.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>

#include "cli_support.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/text_input.hpp"
#include "vibid/ident/frf_io.hpp"
#include "vibid/ident/sample_instants.hpp"

namespace vibid::cli {

void AddEstimationOptions(CLI::App* cmd, EstimationArgs& a, bool require_columns,
                          const std::string& kind_default) {
  a.kind = kind_default;
  auto* force =
      cmd->add_option("--force", a.force, "Force column of the recording, NAME[:UNIT|*FACTOR] (N)");
  auto* resp = cmd->add_option("--response", a.responses,
                               "Response column(s), comma separated, NAME[:UNIT|*FACTOR]");
  if (require_columns) {
    force->required();
    resp->required();
  }
  cmd->add_option("--estimator", a.estimator,
                  "FRF estimator: h1 (noise on the output), h2 (noise on the input), hv")
      ->capture_default_str();
  auto* impact = cmd->add_flag(
      "--impact", a.impact,
      "Hammer test: one record per detected hit, force and exponential windows (the default when\n"
      "the force is a train of short pulses)");
  cmd->add_flag("--welch", a.welch, "Welch averaging even when the force looks like hammer hits")
      ->excludes(impact);
  cmd->add_option("--window", a.window,
                  "Welch window: rect, hann, hamming, blackmanharris, flattop")
      ->capture_default_str();
  cmd->add_option("--segment", a.segment,
                  "Welch segment length in samples (default: a power of two, at most 4096 and a "
                  "quarter of the record)");
  cmd->add_option("--overlap", a.overlap, "Welch overlap in samples (default: half a segment)");
  cmd->add_option("--detrend", a.detrend, "Welch per-segment detrend: none, constant")
      ->capture_default_str();
  cmd->add_option("--sensor", a.sensor, "What the response channels measure: acc, vel, disp")
      ->capture_default_str();
  cmd->add_option("--kind", a.kind, "FRF to produce: receptance, mobility, accelerance")
      ->capture_default_str();
  cmd->add_option("--fs-hz", a.fs_hz, "Sample rate (Hz) when the recording has no t_s column")
      ->check(PositiveNumber());
  cmd->add_option("--trigger", a.impact_options.trigger_fraction,
                  "Impact: hit threshold as a fraction of the largest force")
      ->capture_default_str();
  cmd->add_option("--pretrigger-s", a.impact_options.pretrigger_s,
                  "Impact: seconds kept before each hit (default: 1/64 of the hit record)");
  cmd->add_option("--record-s", a.impact_options.record_s,
                  "Impact: length of each hit's record, s (default: the shortest hit spacing)")
      ->check(NonNegativeNumber());
  cmd->add_option(
         "--force-window-s", a.impact_options.force_window_s,
         "Impact: force kept up to this time after the trigger, s (default: twice the pulse width)")
      ->check(NonNegativeNumber());
  cmd->add_option("--exp-window", a.impact_options.exp_window_end,
                  "Impact: exponential window on force and responses, its value at the record end "
                  "(0: none); damping is corrected for it")
      ->check(NonNegativeNumber());
  cmd->add_option(
         "--double-hit-window-s", a.impact_options.double_hit_window_s,
         "Impact: pulses closer than this to the previous one are rebounds of the same hit, s")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  cmd->add_flag("--keep-bad-hits", a.keep_bad_hits,
                "Impact: use double hits and clipped hits (only flag them)");
}

namespace {

std::size_t DefaultSegment(std::size_t samples) {
  std::size_t seg = 4096;
  while (seg > 16 && seg > samples / 4) seg /= 2;
  return seg;
}

}  // namespace

namespace {

/// Moves every response to the force's sampling instant when the recording states the instants
/// (a board's recording does); says what it did, or nothing for a recording without them.
std::string CompensateInstants(const std::string& path, ident::Frf& frf) {
  const std::optional<ident::SampleInstants> instants = ident::ReadSampleInstants(path);
  if (!instants) return {};
  const auto instant_of = [&](const std::string& column) {
    const std::optional<double> t = instants->Of(column);
    Require(t.has_value(),
            path + ": the header's sample_instants_us does not name column '" + column + "'");
    return *t;
  };
  const double force_s = instant_of(frf.force_name);
  std::vector<double> response_s;
  std::ostringstream text;
  text.precision(6);
  text << "sampling instants compensated (each response moved to " << frf.force_name
       << "'s instant, H x exp(j omega (t_force - t_response))):";
  for (const std::string& name : frf.response_names) {
    response_s.push_back(instant_of(name));
    text << " " << name << " " << (response_s.back() - force_s) * 1e6 << " us;";
  }
  ident::CompensateSampleInstants(frf, force_s, response_s);
  std::string s = text.str();
  s.back() = '\n';
  return s;
}

}  // namespace

Estimated EstimateFromRecording(const std::string& path, const EstimationArgs& a) {
  Require(!a.force.empty(), "--force is required to estimate an FRF from the recording " + path);
  Require(!a.responses.empty(),
          "--response is required to estimate an FRF from the recording " + path);
  const ColumnSpec fspec = ParseColumnSpec(a.force);
  const std::vector<ColumnSpec> rspecs = ParseColumnList(a.responses);
  RecordingOptions ro;
  if (a.fs_hz > 0.0) ro.fs_hz = a.fs_hz;
  // Only the channels asked for must be numbers: a recording may carry other columns (notes).
  ro.channels.push_back(fspec.name);
  for (const ColumnSpec& spec : rspecs) ro.channels.push_back(spec.name);
  const Recording rec = LoadRecording(path, ro);
  // Channels as the estimation reads them: the recording's own column where the spec does not
  // scale it (x * 1 is x), else a scaled copy; no record-length copy of the rest.
  std::deque<Eigen::VectorXd> scaled;
  const auto channel = [&](const ColumnSpec& spec) -> const Eigen::VectorXd& {
    if (spec.scale == 1.0) return rec.table.Column(spec.name);
    return scaled.emplace_back(rec.Signal(spec));
  };
  const Eigen::VectorXd& force = channel(fspec);
  std::vector<const Eigen::VectorXd*> responses;
  std::vector<std::string> names;
  for (const ColumnSpec& spec : rspecs) {
    responses.push_back(&channel(spec));
    names.push_back(spec.name);
  }
  const ident::Estimator est = ident::ParseEstimator(a.estimator);
  const ident::Quantity sensor = ident::ParseQuantity(a.sensor);
  const ident::Quantity kind = ident::ParseQuantity(a.kind);
  // Welch options are checked whichever path runs: a typo must not pass silently because the
  // record turned out to be a hammer test.
  const ident::Window window = ident::ParseWindow(a.window);
  Require(a.detrend == "none" || a.detrend == "constant",
          "--detrend must be none or constant, not '" + a.detrend + "'");
  Require(a.overlap < 0 || a.segment == 0 || static_cast<std::size_t>(a.overlap) < a.segment,
          "--overlap must be smaller than the segment");
  Estimated out;
  bool impact = a.impact;
  if (!a.impact && !a.welch) {
    const ident::ExcitationCheck check = ident::ClassifyExcitation(force, rec.fs_hz);
    impact = check.impact;
    out.note =
        path + ": " + check.description + ": " +
        (impact ? "processed as an impact test, one record per hit (--welch forces Welch averaging)"
                : "Welch averaging (--impact forces per-hit records)");
  }
  if (impact) {
    ident::ImpactOptions io = a.impact_options;
    io.reject_bad_hits = !a.keep_bad_hits;
    Eigen::MatrixXd resp(force.size(), static_cast<Eigen::Index>(responses.size()));
    for (std::size_t j = 0; j < responses.size(); ++j)
      resp.col(static_cast<Eigen::Index>(j)) = *responses[j];
    ident::ImpactResult r = ident::EstimateImpactFrf(force, resp, rec.fs_hz, io, est, sensor);
    out.frf = std::move(r.frf);
    out.hits = std::move(r.hits);
    for (const std::string& w : r.warnings) out.warnings.push_back(path + ": " + w);
    out.record_samples = r.record_samples;
  } else {
    ident::WelchOptions wo;
    wo.window = window;
    wo.detrend = a.detrend == "constant" ? ident::Detrend::kConstant : ident::Detrend::kNone;
    wo.segment_samples = a.segment > 0 ? a.segment : DefaultSegment(rec.samples());
    Require(wo.segment_samples <= rec.samples(), path + ": " + std::to_string(rec.samples()) +
                                                     " samples, fewer than one --segment of " +
                                                     std::to_string(wo.segment_samples));
    Require(a.overlap < 0 || static_cast<std::size_t>(a.overlap) < wo.segment_samples,
            "--overlap must be smaller than the segment");
    wo.overlap_samples =
        a.overlap >= 0 ? static_cast<std::size_t>(a.overlap) : wo.segment_samples / 2;
    const ident::CrossSpectra s = ident::WelchSpectra(force, responses, rec.fs_hz, wo);
    out.frf = ident::FrfFromSpectra(s, est, sensor);
    out.record_samples = wo.segment_samples;
  }
  out.frf.response_names = names;
  out.frf.force_name = fspec.name;
  out.compensation = CompensateInstants(path, out.frf);
  out.frf = ident::ConvertFrf(out.frf, kind);
  return out;
}

ident::Frf LoadOrEstimate(const std::string& path, const EstimationArgs& a,
                          std::vector<std::string>& notes) {
  const ident::Quantity kind = ident::ParseQuantity(a.kind);
  const bool uff = path.size() > 4 && (path.substr(path.size() - 4) == ".uff" ||
                                       path.substr(path.size() - 4) == ".unv");
  if (uff) return ident::ConvertFrf(ident::LoadFrf(path), kind);
  // The first bytes tell an FRF file from a recording: a recording is not read whole twice.
  RequireReadableSize(path, kMaxCsvFileBytes);
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("cannot open '" + path + "': " + std::strerror(errno));
  std::string head(256, '\0');
  file.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(file.gcount()));
  // Said before anything else: an empty file is neither an FRF nor a recording missing its --force.
  Require(head.size() == 256 || head.find_first_not_of(" \t\r\n") != std::string::npos,
          path + ": empty file");
  if (ident::LooksLikeFrfCsv(head)) {
    const std::string text = ReadFileText(path);
    return ident::ConvertFrf(ident::ParseFrfCsv(text, path), kind);
  }
  Estimated e = EstimateFromRecording(path, a);
  // Said on stderr too: a user who did not ask for a processing mode should see which one ran.
  KeepEstimationNotes(path, e, true, notes);
  return std::move(e.frf);
}

void KeepEstimationNotes(const std::string& path, const Estimated& e, bool say_note,
                         std::vector<std::string>& notes) {
  if (!e.note.empty()) {
    if (say_note) std::cerr << "vibid: note: " << e.note << "\n";
    notes.push_back(e.note);
  }
  for (const std::string& w : e.warnings) {
    std::cerr << "vibid: warning: " << w << "\n";
    notes.push_back(w);
  }
  if (!e.compensation.empty())
    notes.push_back(path + ": " + e.compensation.substr(0, e.compensation.size() - 1));
  std::istringstream in(DescribeHits(e.hits));
  for (std::string line; std::getline(in, line);) notes.push_back(path + ": " + line);
}

ident::Frf JoinColumns(const std::vector<ident::Frf>& frfs,
                       const std::vector<std::string>& sources) {
  Require(!frfs.empty(), "no FRF given");
  ident::Frf out = frfs.front();
  for (std::size_t i = 1; i < frfs.size(); ++i) {
    const ident::Frf& f = frfs[i];
    Require(
        f.freq_hz.size() == out.freq_hz.size() && (f.freq_hz - out.freq_hz).cwiseAbs().maxCoeff() <=
                                                      1e-6 * out.freq_hz.cwiseAbs().maxCoeff(),
        sources[i] + ": frequency lines differ from " + sources[0] +
            "'s; estimate both the same way");
    Require(f.quantity == out.quantity,
            sources[i] + ": FRF kind differs from " + sources[0] + "'s");
    const Eigen::Index c = out.h.cols();
    out.h.conservativeResize(Eigen::NoChange, c + f.h.cols());
    out.coherence.conservativeResize(Eigen::NoChange, c + f.h.cols());
    out.h.rightCols(f.h.cols()) = f.h;
    out.coherence.rightCols(f.h.cols()) = f.coherence;
    out.response_names.insert(out.response_names.end(), f.response_names.begin(),
                              f.response_names.end());
    out.exp_window_tau_s = std::max(out.exp_window_tau_s, f.exp_window_tau_s);
    Require(f.pretrigger_s == out.pretrigger_s, sources[i] + ": pretrigger differs from " +
                                                    sources[0] + "'s; estimate both the same way");
  }
  return out;
}

std::string DescribeHits(const std::vector<ident::Hit>& hits) {
  std::ostringstream out;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const ident::Hit& h = hits[i];
    char line[256];
    std::snprintf(line, sizeof line, "hit %zu at %.4f s, peak %.4g, %s%s%s\n", i + 1, h.t_s,
                  h.peak_n, h.used ? "used" : "rejected", h.note.empty() ? "" : ": ",
                  h.note.c_str());
    out << line;
  }
  return out.str();
}

nlohmann::json ModesToJson(const std::vector<ident::ModeEstimate>& modes) {
  nlohmann::json arr = nlohmann::json::array();
  for (const auto& m : modes) {
    nlohmann::json j;
    j["omega_rad_s"] = m.omega_rad_s;
    j["freq_hz"] = m.freq_hz;
    j["zeta"] = m.zeta;
    j["ratio"] = std::isfinite(m.ratio) ? nlohmann::json(m.ratio) : nlohmann::json(nullptr);
    j["shape"] = std::vector<double>(m.shape.data(), m.shape.data() + m.shape.size());
    if (m.HasIntervals()) {
      const auto pair = [](const std::array<double, 2>& ci) {
        return std::isfinite(ci[0]) && std::isfinite(ci[1]) && ci[1] > ci[0]
                   ? nlohmann::json{ci[0], ci[1]}
                   : nlohmann::json(nullptr);
      };
      j["ci95"] = {{"omega_rad_s", pair(m.omega_ci95_rad_s)},
                   {"zeta", pair(m.zeta_ci95)},
                   {"ratio", pair(m.ratio_ci95)}};
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
                    "fit_band_hz", "rms_relative_error"},
                   "modes file " + source);
  std::vector<ident::ModeEstimate> modes;
  std::size_t i = 0;
  for (const auto& m : json["modes"]) {
    ++i;
    const std::string where = source + ": mode " + std::to_string(i);
    Require(m.is_object() && m.contains("omega_rad_s") && m["omega_rad_s"].is_number(),
            where + ": omega_rad_s missing or not a number");
    RequireKnownKeys(m, {"omega_rad_s", "freq_hz", "zeta", "ratio", "shape", "ci95"},
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
      RequireKnownKeys(m["ci95"], {"omega_rad_s", "zeta", "ratio"},
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

std::string ModesTable(const std::vector<ident::ModeEstimate>& modes) {
  std::ostringstream out;
  bool intervals = false;
  for (const auto& m : modes) intervals = intervals || m.HasIntervals();
  if (intervals) {
    out << "mode   freq_hz      omega_rad_s (95 %)     zeta (95 %)             ratio a1/a2 (95 %)  "
           " shape\n";
  } else {
    out << "mode   freq_hz      omega_rad_s  zeta       ratio a1/a2  shape\n";
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
  for (std::size_t i = 0; i < modes.size(); ++i) {
    const auto& m = modes[i];
    char line[256];
    if (intervals) {
      std::snprintf(line, sizeof line, "%-6zu %-12.5g %-22s %-23s %-20s", i + 1, m.freq_hz,
                    pm(m.omega_rad_s, m.omega_ci95_rad_s, "%.6g").c_str(),
                    pm(m.zeta, m.zeta_ci95, "%.4g").c_str(),
                    pm(m.ratio, m.ratio_ci95, "%.5g").c_str());
    } else {
      std::snprintf(line, sizeof line, "%-6zu %-12.5g %-12.5g %-10.4g %-12.5g", i + 1, m.freq_hz,
                    m.omega_rad_s, m.zeta, m.ratio);
    }
    out << line;
    for (Eigen::Index j = 0; j < m.shape.size(); ++j) {
      std::snprintf(line, sizeof line, " %.5g", m.shape[j]);
      out << line;
    }
    out << "\n";
  }
  return out.str();
}

}  // namespace vibid::cli
