// What a live hammer test shows (HammerSession::Snapshot): the hits with their verdicts and the
// operator's choices, the FRF and modes over the accepted hits, and one hit's record for drawing.
// Plain copies, free of the session and its device types; result_json.hpp gives their JSON.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "vibid/ident/modes.hpp"
#include "vibid/ident/spectral.hpp"

namespace vibid::workflow {

/// One hit as the page lists it.
struct SessionHit {
  std::size_t index = 0;  ///< 1-based, as frf-estimate numbers the hits of the recording.
  double t_s = 0.0;       ///< Trigger time from the recording's first sample.
  double peak_n = 0.0;    ///< Peak force above the baseline.
  /// ok, double hit, clipped, too weak, truncated (the first that applies).
  std::string verdict;
  std::string reason;  ///< The checks' notes; empty when ok.
  bool accepted = false;
  bool by_operator = false;  ///< Accepted or rejected by the operator rather than the verdict.
};

/// A hit's record for drawing: time from the trigger, the force (offset off), the force window
/// the FRF applied (exponential window included), and each response (offset off).
struct HitTraces {
  std::size_t index = 0;
  Eigen::VectorXd t_s;
  Eigen::VectorXd force;
  Eigen::VectorXd force_window;
  Eigen::MatrixXd responses;
  std::vector<std::string> response_names;
};

/// What the page draws; a copy, taken under the session's lock.
struct HammerSnapshot {
  std::uint64_t version = 0;  ///< Changes whenever anything below does.
  std::size_t samples = 0;
  double fs_hz = 0.0;
  bool finished = false;
  /// Hits sampled but not yet judged (their record is not complete).
  std::size_t pending_hits = 0;
  std::vector<SessionHit> hits;
  std::size_t accepted = 0;
  /// Over the accepted hits (kind as the options ask; receptance by default): magnitude, phase,
  /// coherence per response. Empty (no lines) before a hit is accepted.
  ident::Frf frf;
  /// Every warning the library gives on the test so far, as `vibid modes` prints them: the
  /// estimation's (double hits used, usable band...), then the modes' (no intervals...).
  std::vector<std::string> warnings;
  /// Modes, 95 % intervals and the stabilization diagram after the last change; none before.
  std::optional<ident::ModeIdentification> modes;
  std::string modes_error;  ///< Why there are no modes (too few hits for a resonance...).
  /// The band the modes were identified in (Hz: the stabilization diagram's, or the curve fit's);
  /// both 0 without modes. What the FRF is shown over unless all lines are asked for.
  double band_min_hz = 0.0;
  double band_max_hz = 0.0;
  double last_update_ms = 0.0;  ///< Time the last judgement and FRF update took.
  double last_modes_ms = 0.0;   ///< Time the last mode identification took.
};

}  // namespace vibid::workflow
