// The limits the self-test judges a board's measurements against (wire::SelfTestCheck).
#pragma once

#include <cstdint>

#include "vibid/shared/wire/commands.hpp"

namespace vibid::fw {

/// HSE against the host's USB start-of-frame: +-100 ppm. The 8 MHz crystal's own tolerance is
/// far inside it; a board outside it has the wrong crystal or load capacitors (the USB full-speed
/// host's SOF is itself within +-500 ppm, USB 2.0 §7.1.11, so the check cannot be finer than
/// the host).
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
