// What get-info's health page and the self-test's answers mean, in words and numbers: the
// brown-out level and when it is too low, each check's value, unit and verdict. The CLI prints
// these; the decisions (what warns, how a value reads) live here.
#pragma once

#include <optional>
#include <string>

#include "vibid/shared/wire/commands.hpp"

namespace vibid::device {

/// "level3", "level2", "level1", "off" or "unknown".
const char* BrownOutName(wire::BrownOut level);

/// The warning for a brown-out reset below level 3 (2.7 V, the least supply the x32 flash
/// programming of a calibration commit takes) naming the way to set it; empty at level 3 and
/// when the board does not say (kUnknown).
std::optional<std::string> BrownOutWarning(wire::BrownOut level);

/// "power-on", "reset-pin", ..., "unknown".
const char* ResetCauseName(wire::ResetCause cause);

/// "crystal", "crystal-did-not-start", "crystal-wrong-frequency", "pll-did-not-lock" or
/// "unknown" (a board that does not say, or a number this host does not know).
const char* ClockStateName(std::uint32_t state);

/// The clock line of vibid info: the state in words with the crystal as the board measured it
/// ("crystal (measured 8.000 MHz)", "internal oscillator: the crystal measured 12.000 MHz, more
/// than 2 % from the 8 MHz the image was built for"); nullopt when the board does not say.
std::optional<std::string> ClockText(const wire::HealthInfoResponse& health);

/// What a self-test value was measured against, as printed ("usb-frames", "lse", "mid-code",
/// "calibration"); "" for none.
const char* SelfTestReferenceName(wire::SelfTestReference reference);

/// A check's value: mantissa x 10^exp10.
double SelfTestValue(const wire::SelfTestResponse& r);

/// The unit as printed: "ppm", "V", "LSB rms", "LSB", "count"; "" for the checks whose value
/// is a name or a CRC.
const char* SelfTestUnitName(wire::SelfTestUnit unit);

/// The value as printed: a number with the digits the board sent, "0x1234abcd" for a CRC, the
/// slot state ("erased", "valid", "damaged"), the brown-out level or the reset cause's name;
/// "-" when the check is unavailable.
std::string SelfTestValueText(const wire::SelfTestResponse& r);

/// "pass", "FAIL" or "unavailable".
const char* SelfTestVerdictName(wire::SelfTestVerdict verdict);

}  // namespace vibid::device
