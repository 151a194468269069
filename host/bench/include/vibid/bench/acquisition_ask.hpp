// An acquisition as the page asks for it (POST /api/acquire, /api/budget), read strictly: every
// key known, every value in range, or an InputError naming it (the server answers 400 and the
// board is not touched).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vibid/shared/wire/commands.hpp"

namespace vibid::bench {

struct AcquisitionAsk {
  /// The board's sample period: a whole number of microseconds, as the board takes it.
  std::uint32_t sample_period_us = 200;
  std::uint8_t channel_mask = 0;
  double seconds = 0.0;
  /// Records logged per second: the sample rate divided by a decimation the board supports
  /// (2^a 5^b). 0: every sample. `auto_log_rate`: the highest such rate whose log holds the whole
  /// acquisition (device::DecimationThatFits), as the page's "auto" asks.
  double log_rate_hz = 0.0;
  bool auto_log_rate = false;
  bool log_dob = false;  ///< Log the observer's d̂ (the board must hold an observer).
  std::string scenario;  ///< Emulator only: the rig excitation.
  std::vector<float> scenario_params;
  /// The load cell the observer view fits d̂ against ("" : none).
  std::string fit_measured;
  /// The fit's d̂ through a zero-phase 4th-order Butterworth low-pass at this corner first, as
  /// `vibid dob run --lowpass-hz` makes d_hat_lp_n (0: the raw d̂, as `dob compare` scores it).
  double fit_lowpass_hz = 0.0;
};

/// Reads `body` (keys sample_period_us, channels, seconds, log_rate_hz (Hz or "auto"), log_dob,
/// scenario, scenario_params, fit_measured, fit_lowpass_hz); InputError on an unknown key, a wrong
/// type or a value out of range.
AcquisitionAsk ParseAcquisitionAsk(const nlohmann::json& body);

/// The board's acquisition for `ask` on a board that answered `info`, streamed: the decimation of
/// the log rate asked for (auto: the smallest whose log holds the acquisition; 1 when none does,
/// which the preflight then refuses), the record limit of `seconds` at the log rate.
wire::AcqConfigureRequest ConfigFor(const AcquisitionAsk& ask, const wire::InfoResponse& info);

}  // namespace vibid::bench
