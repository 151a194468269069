// What get-info's health page and the self-test's answers mean, in words and numbers: the
// brown-out level and when it is too low, each check's value, unit and verdict. The CLI prints
// these; the decisions (what warns, how a value reads) live here.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "vibid/shared/wire/commands.hpp"

namespace vibid::device {

/// "level3", "level2", "level1", "off" or "unknown".
const char* BrownOutName(wire::BrownOut level);

/// The warning for a brown-out reset below level 3 (2.7 V, the least supply the x32 flash
/// programming of a calibration commit takes) naming the way to set it; empty at level 3 and
/// when the board does not say (kUnknown).
std::optional<std::string> BrownOutWarning(wire::BrownOut level);

/// "power-on", "reset-pin", ..., "fault", "unknown".
const char* ResetCauseName(wire::ResetCause cause);

/// The exception a fault record names: "HardFault", "MemManage", "BusFault", "UsageFault",
/// "NMI", "IRQ n without a handler".
std::string FaultExceptionName(std::uint8_t exception);
/// The fault status bits set in the record's CFSR and HFSR, by their ARMv7-M names
/// ("PRECISERR", "BFARVALID", "FORCED", ...), CFSR's from bit 0 up, then HFSR's.
std::vector<std::string> FaultStatusNames(const wire::FaultInfoResponse& fault);
/// One line for vibid info and selftest: "BusFault at pc 0x08012345, lr 0x08011111; CFSR
/// 0x00008200, HFSR 0x40000000, BFAR 0x40026400 (PRECISERR BFARVALID FORCED)". MMFAR and BFAR
/// appear only when CFSR says they hold the address (MMARVALID, BFARVALID).
std::string FaultText(const wire::FaultInfoResponse& fault);

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
