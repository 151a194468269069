// The JSON forms of identification results, as `vibid ... --json` and report.json write them. The
// Python package and the bench read the same objects, so every front end shows the same numbers.
#pragma once

#include <array>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vibid/ident/intervals.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/ident/updates.hpp"
#include "vibid/workflow/hammer_snapshot.hpp"

namespace vibid::workflow {

/// {"termination", "iterations", "initial_cost", "final_cost", "message"}, for any solver summary
/// with a TerminationName beside its Termination type (ident, numerics and sysid each have one).
template <typename Summary>
nlohmann::json SolverSummaryJson(const Summary& s) {
  return {{"termination", TerminationName(s.termination)},
          {"iterations", s.iterations},
          {"initial_cost", s.initial_cost},
          {"final_cost", s.final_cost},
          {"message", s.message}};
}

/// {"modes": [{omega_rad_s, freq_hz, zeta, ratio, shape, ci95: {omega_rad_s, zeta, ratio}}]}; an
/// interval that could not be estimated is null, never a point.
nlohmann::json ModesToJson(const std::vector<ident::ModeEstimate>& modes);
/// Reads what ModesToJson (or `modes --json`) wrote; refuses unknown keys and bad intervals.
std::vector<ident::ModeEstimate> ModesFromJson(const nlohmann::json& json,
                                               const std::string& source);
/// {"method", "band_hz": [lo, hi], "orders": [...], "poles": [{order, freq_hz, zeta, stable_freq,
/// stable_damping, stable_shape, cluster}], "selected": [{freq_hz, omega_rad_s, zeta, orders,
/// freq_spread, zeta_spread}]}
nlohmann::json DiagramToJson(const ident::StabilizationDiagram& diagram);
/// What `vibid modes --json` prints: the modes, method, responses, warnings, notes, and the
/// stabilization diagram and fit summary when there are.
nlohmann::json ModeIdentificationJson(const ident::ModeIdentification& result,
                                      const std::string& method,
                                      const std::vector<std::string>& responses,
                                      const std::vector<std::string>& notes);

/// Text table of modes (freq, omega, zeta, ratio, shape); with intervals, value +- the 95 %
/// half-width, and n/a for one that could not be estimated.
std::string ModesTable(const std::vector<ident::ModeEstimate>& modes);
/// The table and one line on the stabilization diagram or the curve fit, as `vibid modes` prints.
std::string ModeIdentificationText(const ident::ModeIdentification& result);

/// Sets `KEY_ci95` to [lo, hi] and `KEY_ci95_basis` to how it was estimated, or `KEY_ci95` to
/// null and `KEY_ci95_missing` to why there is none.
void PutInterval(nlohmann::json& j, const std::string& key, const ident::Interval95& ci);
/// The mass update's m, k and c intervals; with `calibration_u` > 0 (the relative standard
/// uncertainty of the load cell's and the response sensor's sensitivities, sensor_calibration.hpp)
/// each carries that calibration part beside its statistical one, `sensors` naming them.
std::array<ident::Interval95, 3> MassUpdateIntervals(const ident::MassUpdateResult& result,
                                                     double calibration_u = 0.0,
                                                     const std::string& sensors = "");
nlohmann::json MassUpdateJson(const ident::MassUpdateResult& result, double calibration_u = 0.0,
                              const std::string& sensors = "");
nlohmann::json StiffnessJson(const ident::StiffnessAverage& average);

/// The snapshot as the page draws it: {version, samples, fs_hz, finished, pending_hits, accepted,
/// hits: [{index, t_s, peak_n, verdict, reason, accepted, decided_by}], frf: {kind, freq_hz,
/// responses: [{name, magnitude, phase_rad, coherence}]} or null, warnings, modes: ModesToJson
/// (95 % intervals) or null, diagram: DiagramToJson or null, modes_error, timing_ms: {update,
/// modes}}.
nlohmann::json HammerSnapshotJson(const HammerSnapshot& snapshot);
/// {index, t_s, force, force_window, responses: [{name, values}]}.
nlohmann::json HitTracesJson(const HitTraces& traces);
/// hits.json: {"format": kHitListFormat, "hits": [{index, t_s, peak_n, verdict, reason, accepted,
/// decided_by}]}.
nlohmann::json HitListJson(const std::vector<SessionHit>& hits);

}  // namespace vibid::workflow
