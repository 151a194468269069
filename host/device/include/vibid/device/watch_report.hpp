// The board's residual test ("model stale") as `vibid info`, `vibid monitor` and the Python
// Board show it: get-info's watch page in JSON and in words.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "vibid/shared/wire/watch_info.hpp"

namespace vibid::device {

/// `info --json`'s "model_stale": null without a test (no page, or a calibration without one),
/// else {"state": "watching" | "idle", "stale": bool, "statistic", "threshold", "last_z" (in
/// spreads of the window mean), "windows", "window_samples", "tripped_at_tick" and
/// "tripped_at_s" (null while not stale; seconds from the acquisition's start at
/// sample_period_us), "trip_statistic", "clamps"}.
nlohmann::json WatchJson(const std::optional<wire::WatchInfoResponse>& watch,
                         std::uint32_t sample_period_us);

/// One line: "none (...)", "in control: g 1.25 of h 8.25 after 812 windows of 1000 samples" or
/// "STALE since tick 811999 (162.4 s, g 8.50 > h 8.25); g now 12.25". An idle test is said to
/// wait for the sampling when `observer_on` (get-status's dob_running: started, the board idle;
/// the test runs while it samples), else "(observer stopped)".
std::string WatchText(const std::optional<wire::WatchInfoResponse>& watch,
                      std::uint32_t sample_period_us, bool observer_on = false);

}  // namespace vibid::device
