// FRF estimation from a recording the way every front end does it: the columns chosen by name
// (with unit or factor), impact or Welch decided from the force channel unless asked, the default
// Welch segment, the hit verdicts, the sampling-instant compensation a board's recording states.
// The CLI (`frf-estimate`, `modes`, `identify`), the bench and the Python package call these.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "vibid/common/csv.hpp"
#include "vibid/ident/impact.hpp"
#include "vibid/ident/recording_facts.hpp"
#include "vibid/ident/ringdown.hpp"
#include "vibid/ident/spectral.hpp"

namespace vibid::workflow {

/// How to process a recording. The text fields take the CLI's words (`h1`, `hann`, `acc`,
/// `receptance`...) and are checked by Validate (a typo is refused whichever path runs).
struct EstimationOptions {
  std::string force;             ///< NAME[:UNIT|*FACTOR] of the force column (N).
  std::string responses;         ///< Comma-separated NAME[:UNIT|*FACTOR] of the response columns.
  std::string estimator = "h1";  ///< h1, h2, hv.
  bool impact = false;           ///< Per-hit records even when the force does not look like hits.
  bool welch = false;            ///< Welch averaging even when the force looks like hits.
  std::string window = "hann";   ///< Welch window.
  std::string detrend = "none";  ///< Welch per-segment detrend: none, constant.
  /// What the responses measure: acc, vel, disp, one for all or a comma list with one per
  /// response; empty: each from its column's unit (ResponseQuantities).
  std::string sensor;
  std::string kind = "receptance";  ///< FRF produced: receptance, mobility, accelerance.
  std::size_t segment = 0;          ///< Welch segment (samples); 0: DefaultSegment.
  long overlap = -1;                ///< Welch overlap (samples); < 0: half a segment.
  double fs_hz = 0.0;               ///< Sample rate when the recording has no t_s column.
  ident::ImpactOptions impact_options;
  bool keep_bad_hits = false;  ///< Use double and clipped hits (only flag them).
  /// Impact: the hits to average, "1,2,4" (1-based, numbered as the hit notes number them),
  /// whatever their verdicts; empty: the verdicts decide.
  std::string use_hits;
  /// Impact: a hit list a hammer session saved (hits.json): its accepted hits are averaged.
  std::string hits_file;

  /// Throws InputError naming the option and its allowed values.
  void Validate() const;
};

/// What each response measures, so that accelerometers and encoders can share one test: the
/// unit given in its spec (`:mm`, `:g`, `:m/s`), else a board column's unit suffix (`_m_s2`
/// acceleration, `_m_s` velocity, `_m` displacement: acc1_m_s2, x1_m), else `sensor` (one
/// quantity for all, or a comma list with one per response), else acceleration. A `sensor` that
/// contradicts a column's unit is refused, naming the column and the way out.
std::vector<ident::Quantity> ResponseQuantities(const std::vector<ColumnSpec>& responses,
                                                const std::string& sensor);

/// The quantity an estimation of responses of these quantities runs in: the highest derivative
/// among them (acceleration if any), so that aligning the others multiplies by j omega and
/// never divides by it at the DC line.
ident::Quantity CommonQuantity(const std::vector<ident::Quantity>& measured);

/// An FRF estimated as if every response measured frf.quantity (CommonQuantity of `measured`):
/// each column whose response measured a lower derivative is multiplied by (j omega)^(order
/// difference), so every column is the FRF of one kind (H = X / F of a displacement becomes
/// -omega^2 X / F). Columns already of frf.quantity are left as they are.
void AlignMeasuredQuantities(ident::Frf& frf, const std::vector<ident::Quantity>& measured);

/// The Welch segment used when none is given: a power of two, at most 4096 and a quarter of the
/// record (at least 16).
std::size_t DefaultSegment(std::size_t samples);

struct Estimated {
  ident::Frf frf;
  std::vector<ident::Hit> hits;  ///< Impact processing only.
  /// Impact processing: the used hits' responses after their force windows, for the check of
  /// amplitude-dependent damping (ident/ringdown.hpp).
  ident::RingDowns ringdowns;
  std::size_t record_samples = 0;
  bool impact = false;  ///< Which processing ran.
  /// One line saying how the recording was processed when that was chosen automatically.
  std::string note;
  std::vector<std::string> warnings;  ///< From the impact processing (double hits, usable band).
  /// The sampling-instant compensation applied (one line ending in '\n'), empty when the recording
  /// states no instants.
  std::string compensation;
};

/// The converter's limits of a recording's column in the units its spec scales it to: the rails
/// its sidecar states (`facts`, null when it has none), else for a board's raw-count column the
/// converter its name implies (force1_counts: 0 .. 4095); unknown otherwise (the clip check is
/// then unavailable for it, and said so).
ident::ImpactOptions::ConverterLimits ConverterLimitsOf(const ColumnSpec& spec,
                                                        const ident::RecordingFacts* facts);

/// Reads a recording and estimates the FRF of every response to the force, converted to
/// `options.kind`. Per-hit impact records when `impact` is set or, unless `welch` is, when the
/// force is a train of short pulses (ident::ClassifyExcitation); Welch averaging otherwise.
Estimated EstimateFromRecording(const std::string& path, const EstimationOptions& options);

/// The same on signals already in memory (SI units; `force`/`responses` names only label the
/// result, the column specs of `options` are not used). No sampling-instant compensation unless
/// `instants_s` gives one instant per channel (force first) relative to the frame.
Estimated EstimateFromSignals(const Eigen::Ref<const Eigen::VectorXd>& force,
                              const Eigen::Ref<const Eigen::MatrixXd>& responses, double fs_hz,
                              const std::string& force_name,
                              const std::vector<std::string>& response_names,
                              const EstimationOptions& options,
                              const std::vector<double>& instants_s = {});

/// An FRF file (.uff/.unv, or a CSV with freq_hz) as it is; any other CSV is a recording and is
/// estimated first (then `hits`, `note`... say how). The FRF is converted to `options.kind`.
Estimated LoadOrEstimate(const std::string& path, const EstimationOptions& options);

/// The lines a report keeps about one estimation: its note, warnings, compensation and one line
/// per hit, each prefixed with `path: ` (the note as it is: it names the path already).
std::vector<std::string> EstimationNotes(const std::string& path, const Estimated& e);

/// Joins FRFs of the same frequency lines column-wise (responses of one test in several files).
ident::Frf JoinColumns(const std::vector<ident::Frf>& frfs,
                       const std::vector<std::string>& sources);

/// "1,2,4" -> {1, 2, 4}: hit numbers from 1, each once, in increasing order.
std::vector<std::size_t> ParseHitList(const std::string& list);

/// The "format" of a hammer session's hit list.
inline constexpr const char* kHitListFormat = "vibid-hammer-hits";

/// The accepted hits of a hit list a hammer session saved (HammerSession::Save's hits.json).
std::vector<std::size_t> ReadAcceptedHits(const std::string& path);

/// One line per hit: time, peak, used or why not.
std::string DescribeHits(const std::vector<ident::Hit>& hits);

}  // namespace vibid::workflow
