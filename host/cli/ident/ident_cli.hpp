// Pieces shared by the identification commands: FRF estimation options on a recording, loading an
// FRF file or estimating one from a recording, and JSON for modes and solver summaries.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "vibid/ident/impact.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/numerics/least_squares.hpp"
#include "vibid/ident/spectral.hpp"

namespace vibid::cli {

struct EstimationArgs {
  std::string force;
  std::string responses;
  std::string estimator = "h1";
  bool impact = false;
  bool welch = false;
  std::string window = "hann";
  std::string detrend = "none";
  std::string sensor = "acc";
  std::string kind = "receptance";
  std::size_t segment = 0;
  long overlap = -1;
  double fs_hz = 0.0;
  ident::ImpactOptions impact_options;
  bool keep_bad_hits = false;
};

/// Adds --force/--response (required when `require_columns`) and every estimation option.
void AddEstimationOptions(CLI::App* cmd, EstimationArgs& args, bool require_columns,
                          const std::string& kind_default);

struct Estimated {
  ident::Frf frf;
  std::vector<ident::Hit> hits;  ///< Impact mode only.
  std::size_t record_samples = 0;
  /// One line saying how the recording was processed when that was chosen automatically.
  std::string note;
  std::vector<std::string> warnings;  ///< From the impact processing (double hits, usable band).
  /// The sampling-instant compensation applied (one line), empty when the recording states none.
  std::string compensation;
};

/// Reads a recording and estimates the FRF of every response to the force, converted to the
/// requested kind. Per-hit impact records when --impact is given or, unless --welch is, when the
/// force is a train of short pulses (ident::ClassifyExcitation); Welch averaging otherwise.
Estimated EstimateFromRecording(const std::string& path, const EstimationArgs& args);

/// An FRF file (.uff/.unv, or a CSV with freq_hz) as it is; any other CSV is a recording and is
/// estimated first. The result is converted to `args.kind`.
ident::Frf LoadOrEstimate(const std::string& path, const EstimationArgs& args,
                          std::vector<std::string>& notes);

/// Says on stderr what the estimation of `path` warned of (and its processing note when
/// `say_note`), and keeps the note, the warnings and one line per hit in `notes` for the report.
void KeepEstimationNotes(const std::string& path, const Estimated& e, bool say_note,
                         std::vector<std::string>& notes);

/// Joins FRFs of the same frequency lines column-wise (responses of one test in several files).
ident::Frf JoinColumns(const std::vector<ident::Frf>& frfs,
                       const std::vector<std::string>& sources);

/// One line per hit: time, peak, used or why not.
std::string DescribeHits(const std::vector<ident::Hit>& hits);

nlohmann::json ModesToJson(const std::vector<ident::ModeEstimate>& modes);
std::vector<ident::ModeEstimate> ModesFromJson(const nlohmann::json& json,
                                               const std::string& source);
/// {"method", "band_hz": [lo, hi], "orders": [...], "poles": [{order, freq_hz, zeta, stable_freq,
/// stable_damping, stable_shape, cluster}], "selected": [{freq_hz, omega_rad_s, zeta, orders,
/// ...}]}
nlohmann::json DiagramToJson(const ident::StabilizationDiagram& diagram);

/// Text table of modes (freq, omega, zeta, ratio, shape); with intervals, value +- the 95 %
/// half-width.
std::string ModesTable(const std::vector<ident::ModeEstimate>& modes);

}  // namespace vibid::cli
