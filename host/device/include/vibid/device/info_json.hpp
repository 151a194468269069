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
/// "model_stale" (the board's residual test, watch_report.hpp) is null without `watch`; "fault"
/// (the fault handler's record: exception, CFSR, HFSR, MMFAR, BFAR, PC, LR) without `fault`.
nlohmann::json InfoJson(const Connection& c, const wire::InfoResponse& i,
                        const std::optional<wire::ClipResponse>& clips,
                        const std::optional<wire::SamplingInfoResponse>& sampling,
                        const std::optional<wire::HealthInfoResponse>& health,
                        const std::optional<wire::WatchInfoResponse>& watch = std::nullopt,
                        const std::optional<wire::FaultInfoResponse>& fault = std::nullopt);

/// The fault record as JSON (exception and its name, cfsr, hfsr, mmfar, bfar, pc, lr as hex,
/// pc and lr null when the stack was not readable, the status bit names, the text line); null
/// without a record.
nlohmann::json FaultJson(const std::optional<wire::FaultInfoResponse>& fault);

}  // namespace vibid::device
