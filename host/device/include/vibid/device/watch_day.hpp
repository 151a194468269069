// The board's residual test (its "model stale" flag, docs/dob.md) built into a calibration record
// from a calibration-day recording: the observer the record carries is replayed bit for bit on
// the recording's own samples (its inputs as `vibid acquire` wrote them), and dob::DesignWatch
// takes the test's window, scale, in-control statistics and threshold from that replay.
#pragma once

#include <cstdint>
#include <string>

#include "vibid/common/csv.hpp"
#include "vibid/dob/watch_design.hpp"
#include "vibid/shared/wire/calibration_record.hpp"

namespace vibid::device {

struct WatchDayOptions {
  /// False alarms per hour of in-control running (the library's default: one in 1000 hours).
  double false_alarms_per_hour = dob::WatchOptions{}.false_alarms_per_hour;
  /// The shift, in the window mean's spreads, the test catches fastest.
  double shift_spreads = dob::WatchOptions{}.shift_spreads;
  std::uint32_t window_samples = 0;  ///< 0: from the residual's correlation time.
  /// A load cell measuring the force where the observer estimates it ("force1" or "force2"):
  /// r = d_hat - F. Empty: r = d_hat (no external force beyond the observer's own inputs).
  std::string reference;
};

/// Adds the test to `record` (which must carry an observer) from the calibration day `day`,
/// recorded at the observer's rate with its input channels (and the reference load cell's, if
/// named), and returns the design. When the recording holds the board's `d_hat_q31`, the replay
/// must equal it (the day was recorded with this very observer). InputError naming `source`, the
/// cause and the way out otherwise.
dob::WatchDesign AttachWatchTest(wire::CalibrationRecord& record, const Recording& day,
                                 const WatchDayOptions& options, const std::string& source);

/// One line for the user: the window, the threshold, the stated rate and the run lengths.
std::string WatchDesignText(const dob::WatchDesign& design);

}  // namespace vibid::device
