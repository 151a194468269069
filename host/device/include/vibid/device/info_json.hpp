// The board's profile as JSON, as `vibid info --json` prints it and the Python Board's info()
// returns it: identity, capabilities, sampling and link figures, calibration state, counters.
#pragma once

#include <optional>

#include <nlohmann/json.hpp>

#include "vibid/device/connection.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::device {

/// The board kind as `vibid info` names it (stm32f405, qemu-netduinoplus2, emulator, host-test).
const char* BoardName(wire::BoardId board);

/// `clips`, `sampling` and `health` are null in the JSON when absent (a board of protocol 2.0);
/// "model_stale" (the board's residual test, watch_report.hpp) is null without `watch`.
nlohmann::json InfoJson(const Connection& c, const wire::InfoResponse& i,
                        const std::optional<wire::ClipResponse>& clips,
                        const std::optional<wire::SamplingInfoResponse>& sampling,
                        const std::optional<wire::HealthInfoResponse>& health,
                        const std::optional<wire::WatchInfoResponse>& watch = std::nullopt);

}  // namespace vibid::device
