// The limits the self-test judges a board's measurements against (wire::SelfTestCheck).
#pragma once

#include <cstdint>

#include "vibid/shared/wire/commands.hpp"

namespace vibid::fw {

/// HSE against the host's USB start-of-frame: +-600 ppm. The host's frame clock is only required
/// to be within +-500 ppm (USB 2.0: a full-speed frame is 1.000 ms +-500 ns), so the
/// check allows the host's tolerance plus a crystal's own 100 ppm: a good board passes on any
/// compliant host, and a wrong crystal or load capacitors far off still fail. The board's own
/// 32.768 kHz crystal, where it has one, gives the finer figure (kHsePpmLse).
inline constexpr std::int64_t kHseToleranceMicroPpm = 600'000'000;
/// HSE against the LSE: +-100 ppm. A 32.768 kHz watch crystal is within +-20 ppm at 25 C and an
/// HSE crystal within tens of ppm; more means the wrong crystal or load capacitors.
inline constexpr std::int64_t kHseLseToleranceMicroPpm = 100'000'000;
/// VDDA: the board's 3.3 V regulator within +-5 %.
inline constexpr std::int64_t kVddaMinMicroV = 3'135'000;
inline constexpr std::int64_t kVddaMaxMicroV = 3'465'000;
/// Idle noise of a converter channel: at most 4 LSB rms (the sensors' own noise at idle is
/// below 1 LSB; more means a noisy supply, ground or cable).
inline constexpr std::int64_t kNoiseMaxMicroLsbRms = 4'000'000;
/// Idle offset from the channel's own idle code (its calibrated zero, or the converter's mid code
/// for a channel without one): at most 100 LSB (2.4 % of the half range).
inline constexpr std::int64_t kOffsetMaxMicroLsb = 100'000'000;

/// Whether a numeric check's value (mantissa x 10^exp10, in the check's unit) is within its
/// limit; false for a check without one.
bool SelfTestWithinLimit(wire::SelfTestCheck check, std::int64_t mantissa, std::int8_t exp10);

}  // namespace vibid::fw
