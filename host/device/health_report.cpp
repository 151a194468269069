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
         ", below level 3 (2.7 V), the least supply its x32 flash programming takes: a sagging "
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
