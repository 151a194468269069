// What the board's counters and its latest frame mean, in words: clipped samples per channel
// (get-clips) and what read-latest shows when the board is not sampling. The CLI prints these;
// the decisions (what counts, what to say) live here.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::device {

/// "force1 1234 and acc2 7 of 50000 samples clipped (at the converter's end or beyond the
/// calibrated full scale: force1 500 N, acc2 200 m/s2); the values there are not the signal",
/// or "" when no channel clipped. `record` null when the board is uncalibrated.
std::string DescribeClips(const wire::ClipResponse& clips, const wire::CalibrationRecord* record);

/// What a monitor line shows, from read-latest and get-status.
enum class LatestKind : std::uint8_t {
  kLive,     ///< Sampling: the newest frame of the running acquisition.
  kNoFrame,  ///< No frame in the current or last acquisition (none since boot): nothing to show.
  kStopped,  ///< Not sampling: the last frame of the acquisition that ended (or was stopped).
};

/// The board samples only while an acquisition runs (armed or acquiring). Otherwise read-latest
/// holds the last frame of the last acquisition (ticks > 0 in get-status) or nothing at all.
LatestKind ClassifyLatest(const wire::LatestResponse& latest, const wire::StatusResponse& status);

/// Whether the board samples in `state`: armed or acquiring. Done (the record limit reached) and
/// idle (never started, or stopped) are not sampling: the log is kept, nothing new comes.
bool IsSampling(wire::AcqState state);

/// The board's acquisition state in words, as `vibid monitor` and the bench show it: "armed:
/// waiting for the trigger", "sampling", "stopped: the last acquisition ended (N records)",
/// "stopped: the last acquisition was stopped (N records)", "idle: no acquisition since power-up";
/// ", observer on" while the observer is started (dob start).
std::string DescribeAcquisitionState(const wire::StatusResponse& status);

}  // namespace vibid::device
