#include "vibid/device/health_report.hpp"

#include <cmath>
#include <cstdio>
#include <utility>

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
    case wire::ResetCause::kFault: return "fault";
    case wire::ResetCause::kUnknown: break;
  }
  return "unknown";
}

std::string FaultExceptionName(std::uint8_t exception) {
  switch (exception) {
    case 2: return "NMI";
    case 3: return "HardFault";
    case 4: return "MemManage";
    case 5: return "BusFault";
    case 6: return "UsageFault";
    default: break;
  }
  if (exception >= 16) return "IRQ " + std::to_string(exception - 16) + " without a handler";
  return "exception " + std::to_string(exception);
}

std::vector<std::string> FaultStatusNames(const wire::FaultInfoResponse& f) {
  // CFSR: MMFSR 7:0, BFSR 15:8, UFSR 31:16; HFSR VECTTBL 1, FORCED 30, DEBUGEVT 31 (ARMv7-M
  // ARM B3.2.15, B3.2.16; Cortex-M4 generic user guide table 4-27).
  static constexpr std::pair<unsigned, const char*> kCfsr[] = {
      {0, "IACCVIOL"},  {1, "DACCVIOL"}, {3, "MUNSTKERR"},  {4, "MSTKERR"},      {5, "MLSPERR"},
      {7, "MMARVALID"}, {8, "IBUSERR"},  {9, "PRECISERR"},  {10, "IMPRECISERR"}, {11, "UNSTKERR"},
      {12, "STKERR"},   {13, "LSPERR"},  {15, "BFARVALID"}, {16, "UNDEFINSTR"},  {17, "INVSTATE"},
      {18, "INVPC"},    {19, "NOCP"},    {24, "UNALIGNED"}, {25, "DIVBYZERO"}};
  static constexpr std::pair<unsigned, const char*> kHfsr[] = {
      {1, "VECTTBL"}, {30, "FORCED"}, {31, "DEBUGEVT"}};
  std::vector<std::string> names;
  for (const auto& [bit, name] : kCfsr)
    if ((f.cfsr >> bit) & 1u) names.emplace_back(name);
  for (const auto& [bit, name] : kHfsr)
    if ((f.hfsr >> bit) & 1u) names.emplace_back(name);
  return names;
}

std::string FaultText(const wire::FaultInfoResponse& f) {
  char hex[16];
  const auto h = [&hex](std::uint32_t v) {
    std::snprintf(hex, sizeof(hex), "0x%08x", v);
    return std::string(hex);
  };
  std::string text = FaultExceptionName(f.exception);
  if (f.pc == wire::kFaultNoStackedValue && f.lr == wire::kFaultNoStackedValue) {
    text += " with the stack outside RAM (no pc, lr)";
  } else {
    text += " at pc " + h(f.pc) + ", lr " + h(f.lr);
  }
  text += "; CFSR " + h(f.cfsr) + ", HFSR " + h(f.hfsr);
  if ((f.cfsr & (1u << 7)) != 0) text += ", MMFAR " + h(f.mmfar);
  if ((f.cfsr & (1u << 15)) != 0) text += ", BFAR " + h(f.bfar);
  const std::vector<std::string> names = FaultStatusNames(f);
  if (!names.empty()) {
    text += " (";
    for (std::size_t k = 0; k < names.size(); ++k) text += (k == 0 ? "" : " ") + names[k];
    text += ")";
  }
  return text;
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
             ", outside 95-109 % of the one the image was built for (the internal oscillator's "
             "spread over temperature); build it for this board "
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
