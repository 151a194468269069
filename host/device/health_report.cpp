#include "vibid/device/health_report.hpp"

#include <cmath>
#include <cstdio>

namespace vibid::device {

const char* BrownOutName(wire::BrownOut level) {
  switch (level) {
    case wire::BrownOut::kLevel3: return "level3";
    case wire::BrownOut::kLevel2: return "level2";
    case wire::BrownOut::kLevel1: return "level1";
    case wire::BrownOut::kOff: return "off";
    case wire::BrownOut::kUnknown: break;
  }
  return "unknown";
}

std::optional<std::string> BrownOutWarning(wire::BrownOut level) {
  // Nominal thresholds: STM32F405 datasheet, reset and power control characteristics.
  const char* what = nullptr;
  switch (level) {
    case wire::BrownOut::kOff: what = "off (power-on reset only, about 1.8 V)"; break;
    case wire::BrownOut::kLevel1: what = "at level 1 (about 2.1 V)"; break;
    case wire::BrownOut::kLevel2: what = "at level 2 (about 2.4 V)"; break;
    case wire::BrownOut::kLevel3:
    case wire::BrownOut::kUnknown: return std::nullopt;
  }
  return std::string("the board's brown-out reset is ") + what +
         ", below level 3 (2.75-2.88 V), which holds it above the 2.7 V its x32 flash "
         "programming takes: a sagging "
         "supply can lose a calibration commit; set BOR_LEV to level 3 in the option bytes "
         "(docs/board.md, \"Brown-out level\")";
}

const char* ResetCauseName(wire::ResetCause cause) {
  switch (cause) {
    case wire::ResetCause::kPowerOn: return "power-on";
    case wire::ResetCause::kPin: return "reset-pin";
    case wire::ResetCause::kSoftware: return "software";
    case wire::ResetCause::kWatchdog: return "watchdog";
    case wire::ResetCause::kBrownOut: return "brown-out";
    case wire::ResetCause::kLowPower: return "low-power";
    case wire::ResetCause::kUnknown: break;
  }
  return "unknown";
}

const char* ClockStateName(std::uint32_t state) {
  switch (static_cast<wire::ClockState>(state)) {
    case wire::ClockState::kCrystal: return "crystal";
    case wire::ClockState::kCrystalDidNotStart: return "crystal-did-not-start";
    case wire::ClockState::kCrystalWrongFrequency: return "crystal-wrong-frequency";
    case wire::ClockState::kPllDidNotLock: return "pll-did-not-lock";
    case wire::ClockState::kUnknown: break;
  }
  return "unknown";
}

std::optional<std::string> ClockText(const wire::HealthInfoResponse& health) {
  char measured[64] = "";
  if (health.hse_measured_hz != 0)
    std::snprintf(measured, sizeof measured, "%.3f MHz", health.hse_measured_hz / 1e6);
  switch (health.clock) {
    case wire::ClockState::kUnknown: return std::nullopt;
    case wire::ClockState::kCrystal:
      return std::string("crystal") + (measured[0] != 0 ? std::string(" (measured ") + measured +
                                                              " against the internal oscillator)"
                                                        : std::string());
    case wire::ClockState::kCrystalWrongFrequency:
      return std::string("internal oscillator, acquisitions refused: the crystal measured ") +
             measured +
             ", more than 2 % from the one the image was built for; build it for this board "
             "(VIBID_BOARD or VIBID_HSE_HZ, docs/board.md)";
    case wire::ClockState::kCrystalDidNotStart:
      return "internal oscillator, acquisitions refused: the crystal did not start; check the "
             "crystal and its load capacitors";
    case wire::ClockState::kPllDidNotLock:
      return "internal oscillator, acquisitions refused: the PLL did not lock on the crystal";
  }
  return std::nullopt;
}

const char* SelfTestReferenceName(wire::SelfTestReference reference) {
  switch (reference) {
    case wire::SelfTestReference::kUsbFrames: return "usb-frames";
    case wire::SelfTestReference::kLse: return "lse";
    case wire::SelfTestReference::kMidCode: return "mid-code";
    case wire::SelfTestReference::kCalibration: return "calibration";
    case wire::SelfTestReference::kNone: break;
  }
  return "";
}

double SelfTestValue(const wire::SelfTestResponse& r) {
  // Divide for negative exponents: 3300 / 10^3 is 3.3 exactly as a double reads it, where
  // 3300 x 10^-3 is not.
  const double m = static_cast<double>(r.mantissa);
  return r.exp10 < 0 ? m / std::pow(10.0, -r.exp10) : m * std::pow(10.0, r.exp10);
}

const char* SelfTestUnitName(wire::SelfTestUnit unit) {
  switch (unit) {
    case wire::SelfTestUnit::kPpm: return "ppm";
    case wire::SelfTestUnit::kVolt: return "V";
    case wire::SelfTestUnit::kLsbRms: return "LSB rms";
    case wire::SelfTestUnit::kLsb: return "LSB";
    case wire::SelfTestUnit::kCount: return "count";
    case wire::SelfTestUnit::kNone:
    case wire::SelfTestUnit::kCrc32:
    case wire::SelfTestUnit::kSlot:
    case wire::SelfTestUnit::kBrownOut:
    case wire::SelfTestUnit::kResetCause: break;
  }
  return "";
}

std::string SelfTestValueText(const wire::SelfTestResponse& r) {
  if (r.verdict == wire::SelfTestVerdict::kUnavailable) return "-";
  char b[40];
  switch (r.unit) {
    case wire::SelfTestUnit::kCrc32:
      std::snprintf(b, sizeof(b), "0x%08x", static_cast<unsigned>(r.mantissa & 0xFFFFFFFF));
      return b;
    case wire::SelfTestUnit::kSlot:
      switch (static_cast<wire::SelfTestSlot>(r.mantissa)) {
        case wire::SelfTestSlot::kErased: return "erased";
        case wire::SelfTestSlot::kValid: return "valid";
        case wire::SelfTestSlot::kDamaged: return "damaged";
      }
      return "unknown";
    case wire::SelfTestUnit::kBrownOut:
      return BrownOutName(static_cast<wire::BrownOut>(r.mantissa));
    case wire::SelfTestUnit::kResetCause:
      return ResetCauseName(static_cast<wire::ResetCause>(r.mantissa));
    default: break;
  }
  // As many decimals as the board sent: -12345 x 10^-3 reads "-12.345".
  const int decimals = r.exp10 < 0 ? -r.exp10 : 0;
  std::snprintf(b, sizeof(b), "%.*f", decimals, SelfTestValue(r));
  return b;
}

const char* SelfTestVerdictName(wire::SelfTestVerdict verdict) {
  switch (verdict) {
    case wire::SelfTestVerdict::kPass: return "pass";
    case wire::SelfTestVerdict::kFail: return "FAIL";
    case wire::SelfTestVerdict::kUnavailable: break;
  }
  return "unavailable";
}

}  // namespace vibid::device
