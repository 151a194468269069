#include "vibid/workflow/report_page.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "vibid/common/csv.hpp"
#include "vibid/common/atomic_file.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/verdict.hpp"
#include "vibid/dob/compare.hpp"
#include "vibid/ident/identify.hpp"
#include "vibid/model/model.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/report/html.hpp"
#include "vibid/report/stabilization_svg.hpp"
#include "vibid/report/svg_plot.hpp"

namespace vibid::workflow {
namespace {

constexpr const char* kTestColor = "#222222";
constexpr const char* kNominalColor = "#d62728";
constexpr const char* kUpdatedColor = "#1f77b4";
constexpr const char* kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e"};

std::string Fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

std::string Sig(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", v);
  return text;
}

double Get(const nlohmann::json& j, const char* key, const std::string& where) {
  Require(j.contains(key) && j.at(key).is_number(), where + ": missing number \"" + key + "\"");
  return j.at(key).get<double>();
}

// "± half-width (p %)" from `updated_ci95`, or "n/a" with the reason; how it was estimated (or
// why not) goes to `notes` after `label`. Reports written before intervals existed have neither:
// "".
std::string IntervalCell(const nlohmann::json& x, double updated, const std::string& label,
                         const std::string& where, std::vector<std::string>& notes) {
  const auto note = [&notes, &label](const std::string& text) { notes.push_back(label + text); };
  if (!x.contains("updated_ci95")) return "";
  const nlohmann::json& ci = x["updated_ci95"];
  if (ci.is_null()) {
    const std::string why =
        x.contains("updated_ci95_missing") && x["updated_ci95_missing"].is_string()
            ? x["updated_ci95_missing"].get<std::string>()
            : std::string("not estimated");
    note("n/a: " + why);
    return "n/a (" + why + ")";
  }
  Require(ci.is_array() && ci.size() == 2 && ci[0].is_number() && ci[1].is_number(),
          where + ": updated_ci95 must be [lo, hi] or null");
  const double hw = 0.5 * (ci[1].get<double>() - ci[0].get<double>());
  if (x.contains("updated_ci95_basis") && x["updated_ci95_basis"].is_string())
    note(x["updated_ci95_basis"].get<std::string>());
  char text[160];
  std::snprintf(text, sizeof text, "± %.2g (%.2g %%)", hw, 100.0 * hw / std::abs(updated));
  std::string cell = text;
  // Its statistical and calibration parts, when the sensors' calibration is in it.
  if (x.contains("updated_ci95_statistical_half_width") &&
      x.contains("updated_ci95_calibration_half_width") &&
      x["updated_ci95_statistical_half_width"].is_number() &&
      x["updated_ci95_calibration_half_width"].is_number()) {
    std::snprintf(text, sizeof text, ": statistical ± %.2g, calibration ± %.2g",
                  x["updated_ci95_statistical_half_width"].get<double>(),
                  x["updated_ci95_calibration_half_width"].get<double>());
    cell += text;
  }
  return cell;
}

void ValidationTables(const nlohmann::json& report, const std::string& where,
                      const model::Model* truth, report::HtmlPage& page) {
  Require(report.contains("validation") && report["validation"].is_object(),
          where + ": no \"validation\" object");
  const nlohmann::json& v = report["validation"];
  std::vector<std::vector<std::string>> rows;
  const char* quantities[][2] = {
      {"omega_rad_s", "omega (rad/s)"}, {"zeta", "zeta"}, {"ratio", "a1/a2"}};
  const auto add_row = [&rows, &where](std::size_t mode, const std::string& name,
                                       const nlohmann::json& x) {
    std::string test = Sig(Get(x, "test", where));
    if (x.contains("test_ci95")) {
      const nlohmann::json& ci = x["test_ci95"];
      Require(ci.is_array() && ci.size() == 2 && ci[0].is_number() && ci[1].is_number(),
              where + ": test_ci95 must be [lo, hi]");
      char hw[32];
      std::snprintf(hw, sizeof hw, "%.2g", 0.5 * (ci[1].get<double>() - ci[0].get<double>()));
      test += std::string(" ± ") + hw;
    }
    rows.push_back({std::to_string(mode + 1), name, Sig(Get(x, "nominal", where)),
                    Sig(Get(x, "updated", where)), test,
                    Fixed(Get(x, "nominal_dev_percent", where), 2),
                    Fixed(Get(x, "updated_dev_percent", where), 2)});
  };
  for (std::size_t i = 0; i < v.at("modes").size(); ++i) {
    const nlohmann::json& mode = v["modes"][i];
    for (const auto& q : quantities)
      if (mode.contains(q[0])) add_row(i, q[1], mode[q[0]]);
    // More than two responses: each against the driving point's (a1/a3, a2/a3).
    if (!mode.contains("shape_ratios")) continue;
    Require(mode["shape_ratios"].is_array(), where + ": shape_ratios must be an array");
    for (const nlohmann::json& x : mode["shape_ratios"]) {
      Require(x.contains("name") && x["name"].is_string(),
              where + ": each of shape_ratios needs a \"name\"");
      add_row(i, x["name"].get<std::string>(), x);
    }
  }
  page.Table(
      {"mode", "quantity", "nominal", "updated", "test (± 95 %)", "nominal dev %", "updated dev %"},
      rows,
      "Deviation of each model from the test (methods §8); the test's 95 % confidence half-width "
      "where the "
      "modal method gives one (lscf, lsce).");

  std::vector<std::string> header{"position", "quantity", "nominal",
                                  "updated",  "± 95 %",   "change %"};
  const ident::ChainParameters chain =
      truth != nullptr ? ident::ChainOf(*truth) : ident::ChainParameters{};
  if (truth != nullptr) {
    header.push_back("truth");
    header.push_back("updated vs truth %");
  }
  rows.clear();
  std::vector<std::string> notes;
  for (std::size_t p = 0; p < v.at("positions").size(); ++p) {
    const nlohmann::json& pos = v["positions"][p];
    const auto i = static_cast<Eigen::Index>(p);
    struct Q {
      const char* key;
      const char* name;
      double truth;
    };
    const bool have_truth = i < chain.masses_kg.size();
    const double m_true = have_truth ? chain.masses_kg[i] : 0.0;
    const double k_true = have_truth ? chain.springs_n_per_m[i] : 0.0;
    const double c_true = have_truth ? chain.dampers_ns_per_m[i] : 0.0;
    for (const Q& q : {Q{"m_kg", "m (kg)", m_true}, Q{"k_n_per_m", "k (N/m)", k_true},
                       Q{"c_ns_per_m", "c (N·s/m)", c_true}}) {
      if (!pos.contains(q.key)) continue;
      const nlohmann::json& x = pos.at(q.key);
      const double updated = Get(x, "updated", where);
      const bool has_nominal = x.contains("nominal");
      std::vector<std::string> row{
          std::to_string(p + 1),
          q.name,
          has_nominal ? Sig(Get(x, "nominal", where)) : "",
          Sig(updated),
          IntervalCell(x, updated, "position " + std::to_string(p + 1) + ", " + q.name + ": ",
                       where, notes) +
              (x.contains("source") && x["source"].is_string()
                   ? " [" + x["source"].get<std::string>() + "]"
                   : std::string()),
          has_nominal ? Fixed(Get(x, "change_percent", where), 2) : ""};
      if (truth != nullptr) {
        row.push_back(have_truth ? Sig(q.truth) : "");
        row.push_back(have_truth ? Fixed(100.0 * (updated - q.truth) / q.truth, 2) : "");
      }
      rows.push_back(row);
    }
  }
  page.Table(header, rows,
             truth != nullptr ? "Physical parameters: change from nominal, 95 % interval of the "
                                "updated value, and error of the update against the rig's truth."
                              : "Physical parameters: change from nominal and 95 % interval of "
                                "the updated value.");
  if (!notes.empty()) {
    page.Paragraph(
        "How each interval was estimated (docs/identification.md, intervals on m, k and c):");
    page.List(notes);
  }
}

// The identification's verdict at the top of the page, in its colour, a line per reason; a report
// written before reports carried one reads as ok, and the box says none was stated.
void VerdictNotice(const Verdict& v, report::HtmlPage& page) {
  std::vector<std::string> lines;
  for (const VerdictReason& r : v.reasons)
    lines.push_back(std::string(VerdictLevelName(r.level)) + " (" + r.code + "): " + r.text);
  if (!v.stated) lines.push_back("this report states no verdict (written before reports did)");
  std::string title = "Verdict: " + std::string(VerdictLevelName(v.level));
  if (v.Flagged())
    title +=
        ": do not take this model to the board (taken only with "
        "--accept-flagged)";
  page.Notice(VerdictLevelName(v.level), title, lines);
}

// How far each model is from the test, and the flag of an update that fits its own test worse
// than the nominal model.
void ModalDeviationParagraph(const nlohmann::json& report, report::HtmlPage& page) {
  if (!report.contains("validation") || !report["validation"].is_object() ||
      !report["validation"].contains("modal_deviation"))
    return;
  const nlohmann::json& d = report["validation"]["modal_deviation"];
  if (!d.is_object() || !d.contains("nominal_percent") || !d.contains("updated_percent") ||
      !d["nominal_percent"].is_number() || !d["updated_percent"].is_number())
    return;
  char text[240];
  std::snprintf(text, sizeof text,
                "Modal deviation from the test (rms of omega and shape): nominal %.3g %%, updated "
                "%.3g %%.",
                d["nominal_percent"].get<double>(), d["updated_percent"].get<double>());
  page.Paragraph(text);
  const nlohmann::json& v = report["validation"];
  if (v.contains("caution") && v["caution"].is_string())
    page.Paragraph("CAUTION: " + v["caution"].get<std::string>() + ".");
  if (d.value("worse_than_nominal", false)) {
    page.Paragraph(
        "FLAGGED: the updated model fits its own test worse than the nominal model; do not use "
        "it (longer records, more hits, or the other method).");
  }
}

// The band worth looking at: from a fifth of the lowest test mode to three times the highest
// (the rest of the record's band up to Nyquist is noise and the anti-alias roll-off).
void FrfBand(const nlohmann::json& report, double& lo_hz, double& hi_hz) {
  lo_hz = 0.0;
  hi_hz = std::numeric_limits<double>::infinity();
  if (!report.contains("test_modes") || !report["test_modes"].is_array() ||
      report["test_modes"].empty())
    return;
  double f_min = std::numeric_limits<double>::infinity(), f_max = 0.0;
  for (const auto& m : report["test_modes"]) {
    if (!m.contains("freq_hz") || !m["freq_hz"].is_number()) return;
    f_min = std::min(f_min, m["freq_hz"].get<double>());
    f_max = std::max(f_max, m["freq_hz"].get<double>());
  }
  lo_hz = f_min / 5.0;
  hi_hz = f_max * 3.0;
}

void FrfFigures(const std::string& overlay_path, double lo_hz, double hi_hz,
                report::HtmlPage& page) {
  const CsvTable all = ReadCsv(overlay_path);
  Require(all.Has("freq_hz"), overlay_path + ": no column 'freq_hz'");
  std::vector<Eigen::Index> keep;
  const Eigen::VectorXd f_all = all.Column("freq_hz");
  for (Eigen::Index i = 0; i < f_all.size(); ++i) {
    if (f_all[i] >= lo_hz && f_all[i] <= hi_hz) keep.push_back(i);
  }
  Require(keep.size() >= 2, overlay_path + ": fewer than 2 frequency lines between " + Sig(lo_hz) +
                                " and " + Sig(hi_hz) + " Hz");
  CsvTable t;
  t.names = all.names;
  for (const Eigen::VectorXd& c : all.columns) t.columns.push_back(c(keep));
  const Eigen::VectorXd f = t.Column("freq_hz");
  for (const std::string& name : t.names) {
    const std::string suffix = "_test";
    if (name.size() <= suffix.size() ||
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const std::string base = name.substr(0, name.size() - suffix.size());
    std::vector<report::Series> series{
        {.label = "measured", .x = f, .y = t.Column(name), .color = kTestColor}};
    if (t.Has(base + "_nominal")) {
      series.push_back({.label = "nominal model",
                        .x = f,
                        .y = t.Column(base + "_nominal"),
                        .color = kNominalColor,
                        .dashed = true});
    }
    if (t.Has(base + "_updated")) {
      series.push_back({.label = "updated model",
                        .x = f,
                        .y = t.Column(base + "_updated"),
                        .color = kUpdatedColor});
    }
    const std::string io = base.size() >= 3 ? base.substr(1) : base;
    const std::string title = "Receptance |H" + io + "| (response " + io.substr(0, io.size() / 2) +
                              ", hammer " + io.substr(io.size() / 2) + ")";
    page.Figure(
        report::SvgPlot(series, {.title = title,
                                 .x = {"frequency (Hz)", report::Scale::kLog},
                                 .y = {"|H| (m/N)", report::Scale::kLog}}),
        "Measured receptance (first modal test) against the nominal and the updated model.");
  }
}

// The stabilization diagram of the first modal test (`vibid identify` with --method lscf/lsce,
// the default), over the measured driving-point receptance of frf_overlay.csv.
void StabilizationFigure(const nlohmann::json& report, const std::string& overlay_path,
                         report::HtmlPage& page) {
  if (!report.contains("modal_tests") || !report["modal_tests"].is_array() ||
      report["modal_tests"].empty())
    return;
  const nlohmann::json& test = report["modal_tests"][0];
  if (!test.contains("stabilization") || !test["stabilization"].is_object()) return;
  const nlohmann::json& d = test["stabilization"];
  report::StabilizationFigure f;
  f.title =
      "Stabilization diagram (" + d.value("method", std::string("lscf")) + "), first modal test";
  const std::vector<double> band = d.at("band_hz").get<std::vector<double>>();
  Require(band.size() == 2, "report.json: stabilization band_hz must hold two numbers");
  f.freq_min_hz = band[0];
  f.freq_max_hz = band[1];
  for (const auto& p : d.at("poles")) {
    const bool all = p.value("stable_freq", false) && p.value("stable_damping", false) &&
                     p.value("stable_shape", false);
    f.poles.push_back({p.at("freq_hz").get<double>(), p.at("order").get<int>(),
                       all                             ? report::PoleMark::kStable
                       : p.value("stable_freq", false) ? report::PoleMark::kFrequency
                                                       : report::PoleMark::kUnstable});
  }
  for (const auto& c : d.at("selected")) f.chosen_hz.push_back(c.at("freq_hz").get<double>());
  if (f.poles.empty()) return;
  if (std::filesystem::exists(overlay_path)) {
    const CsvTable t = ReadCsv(overlay_path);
    for (const std::string& name : t.names) {
      if (name.size() > 5 && name.compare(name.size() - 5, 5, "_test") == 0) {
        f.frf_freq_hz = t.Column("freq_hz");
        f.frf_magnitude = t.Column(name);
      }
    }
  }
  page.Figure(report::StabilizationSvg(f),
              "Poles of every model order; filled: stable in frequency, damping and shape against "
              "the previous order; "
              "red lines: the poles chosen as modes (clusters of stable poles).");
}

void ObserverSection(const ReportRequest& a, report::HtmlPage& page) {
  const Recording rec = LoadRecording(a.dob_recording);
  const Eigen::VectorXd t = rec.Time();
  const Eigen::VectorXd measured = rec.Signal(ParseColumnSpec(a.measured));
  const auto skip = static_cast<Eigen::Index>(std::llround(a.skip_s * rec.fs_hz));
  Require(2 * skip + 2 <= measured.size(),
          "--skip-s " + std::to_string(a.skip_s) + " s at both ends leaves fewer than 2 samples");
  const Eigen::Index n = measured.size() - 2 * skip;

  std::vector<std::vector<std::string>> rows;
  std::vector<report::Series> series{{.label = "measured (" + a.measured + ")",
                                      .x = t.segment(skip, n),
                                      .y = measured.segment(skip, n),
                                      .color = kTestColor}};
  for (std::size_t i = 0; i < a.estimates.size(); ++i) {
    const std::string& spec = a.estimates[i];
    const std::size_t eq = spec.find('=');
    const std::string column = spec.substr(0, eq);
    const std::string label = eq == std::string::npos ? column : spec.substr(eq + 1);
    Require(!column.empty() && !label.empty(),
            "--estimate '" + spec + "': expected COLUMN or COLUMN=LABEL");
    const Eigen::VectorXd e = rec.Signal(ParseColumnSpec(column));
    const dob::Agreement g =
        dob::CompareSignals(e.segment(skip, n), measured.segment(skip, n), rec.fs_hz, 0.0);
    rows.push_back({label, column, Fixed(g.fit_percent, 2), Fixed(g.correlation, 5), Sig(g.delay_s),
                    Sig(g.rmse_n)});
    series.push_back({.label = label,
                      .x = t.segment(skip, n),
                      .y = e.segment(skip, n),
                      .color = kPalette[i % (sizeof kPalette / sizeof kPalette[0])],
                      .dashed = i > 0});
  }
  page.Table({"estimate", "column", "fit %", "correlation", "delay (s)", "rmse (N)"}, rows,
             "Agreement with the measured force: fit = 100 (1 - |m - e| / |m - mean(m)|), " +
                 Fixed(a.skip_s, 2) + " s left out at each end.");
  page.Figure(report::SvgPlot(series, {.title = "Disturbance estimate against the measured push",
                                       .x = {"time (s)", report::Scale::kLinear},
                                       .y = {"force (N)", report::Scale::kLinear},
                                       .height_px = 380}),
              a.dob_recording);
}

}  // namespace

std::string ReportPage(const ReportRequest& a) {
  Require(!a.identify_dir.empty() || !a.dob_recording.empty(),
          "give --identify DIR, --dob REC.csv, or both");
  Require(a.dob_recording.empty() || (!a.measured.empty() && !a.estimates.empty()),
          "--dob needs --measured COLUMN and at least one --estimate COLUMN[=LABEL]");
  report::HtmlPage page(a.title);
  if (!a.identify_dir.empty()) {
    const std::filesystem::path dir(a.identify_dir);
    const std::string json_path = (dir / "report.json").string();
    const nlohmann::json report = ReadJsonFile(json_path);
    // The keys `identify --report` writes.
    RequireKnownKeys(
        report,
        {"verdict", "updated_model", "validation", "parameters", "test_modes", "mass_tests",
         "modal_tests", "stiffness", "warnings", "notes", "method", "chain_fit", "driving_point"},
        "identification report " + json_path);
    Verdict verdict;
    verdict.stated = report.contains("verdict");
    if (verdict.stated) verdict = VerdictFromJson(report["verdict"], json_path + ": \"verdict\"");
    RequireUsable(verdict, a.accept_flagged, "the identification in " + json_path, "report",
                  "--accept-flagged");
    VerdictNotice(verdict, page);
    if (!a.notes.empty()) page.List(a.notes);
    std::unique_ptr<model::Model> truth;
    if (!a.truth.empty()) truth = std::make_unique<model::Model>(model::LoadModel(a.truth));
    page.Heading("Identification");
    if (report.contains("method") && report["method"].is_string())
      page.Paragraph("Updated values from: " + report["method"].get<std::string>() + ".");
    ModalDeviationParagraph(report, page);
    ValidationTables(report, json_path, truth.get(), page);
    if (report.contains("warnings") && report["warnings"].is_array() &&
        !report["warnings"].empty()) {
      page.Paragraph("Warnings:");
      page.List(report["warnings"].get<std::vector<std::string>>());
    }
    page.Heading("Frequency response functions");
    double lo_hz = 0.0, hi_hz = 0.0;
    FrfBand(report, lo_hz, hi_hz);
    FrfFigures((dir / "frf_overlay.csv").string(), lo_hz, hi_hz, page);
    StabilizationFigure(report, (dir / "frf_overlay.csv").string(), page);
  }
  if (a.identify_dir.empty() && !a.notes.empty()) page.List(a.notes);
  if (!a.dob_recording.empty()) {
    page.Heading("Disturbance observer");
    ObserverSection(a, page);
  }
  return page.Render();
}

}  // namespace vibid::workflow
