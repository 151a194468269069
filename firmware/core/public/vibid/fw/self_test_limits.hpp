// The limits the self-test judges a board's measurements against (wire::SelfTestCheck).
#pragma once

#include <cstdint>

#include "vibid/shared/wire/commands.hpp"

namespace vibid::fw {

/// HSE against the host's USB start-of-frame: +-100 ppm. A crystal's own tolerance is tens of
/// ppm; a board outside the limit has the wrong crystal or load capacitors. The host's frame
/// clock is only required to be within +-500 ppm (USB 2.0: a full-speed frame is 1.000 ms
/// +-500 ns), so a failing board is checked against a second host before the crystal is blamed.
inline constexpr std::int64_t kHseToleranceMicroPpm = 100'000'000;
/// VDDA: the board's 3.3 V regulator within +-5 %.
inline constexpr std::int64_t kVddaMinMicroV = 3'135'000;
inline constexpr std::int64_t kVddaMaxMicroV = 3'465'000;
/// Idle noise of a converter channel: at most 4 LSB rms (the sensors' own noise at idle is
/// below 1 LSB; more means a noisy supply, ground or cable).
inline constexpr std::int64_t kNoiseMaxMicroLsbRms = 4'000'000;
/// Idle offset from the converter's mid code: at most 100 LSB (2.4 % of the half range).
inline constexpr std::int64_t kOffsetMaxMicroLsb = 100'000'000;

/// Whether a numeric check's value (mantissa x 10^exp10, in the check's unit) is within its
/// limit; false for a check without one.
bool SelfTestWithinLimit(wire::SelfTestCheck check, std::int64_t mantissa, std::int8_t exp10);

}  // namespace vibid::fw
