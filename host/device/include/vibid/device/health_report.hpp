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
