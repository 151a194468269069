#include "vibid/device/health_report.hpp"

#include <gtest/gtest.h>

namespace vibid::device {
namespace {

TEST(HealthReport, WarnsBelowLevel3AndNamesTheWayOut) {
  EXPECT_FALSE(BrownOutWarning(wire::BrownOut::kLevel3).has_value());
  EXPECT_FALSE(BrownOutWarning(wire::BrownOut::kUnknown).has_value());  // the board does not say
  for (const auto level :
       {wire::BrownOut::kOff, wire::BrownOut::kLevel1, wire::BrownOut::kLevel2}) {
    const auto w = BrownOutWarning(level);
    ASSERT_TRUE(w.has_value());
    // Level 3: 2.75-2.88 V (DS8626), above the 2.7 V x32 programming takes (RM0090 §3.6.2).
    EXPECT_NE(w->find("level 3 (2.75-2.88 V)"), std::string::npos) << *w;
    EXPECT_NE(w->find("2.7 V"), std::string::npos) << *w;
    EXPECT_NE(w->find("docs/board.md, \"Brown-out level\""), std::string::npos) << *w;
  }
  EXPECT_NE(BrownOutWarning(wire::BrownOut::kLevel1)->find("level 1 (about 2.1 V)"),
            std::string::npos);
  EXPECT_STREQ(BrownOutName(wire::BrownOut::kOff), "off");
  EXPECT_STREQ(BrownOutName(wire::BrownOut::kUnknown), "unknown");
}

TEST(HealthReport, SelfTestValuesReadAsTheBoardSentThem) {
  wire::SelfTestResponse r{.check = 0,
                           .verdict = wire::SelfTestVerdict::kPass,
                           .unit = wire::SelfTestUnit::kPpm,
                           .exp10 = -3,
                           .mantissa = -12345};
  EXPECT_DOUBLE_EQ(SelfTestValue(r), -12.345);
  EXPECT_EQ(SelfTestValueText(r), "-12.345");
  EXPECT_STREQ(SelfTestUnitName(r.unit), "ppm");
  r.unit = wire::SelfTestUnit::kCrc32;
  r.exp10 = 0;
  r.mantissa = 0xCAFEF00D;
  EXPECT_EQ(SelfTestValueText(r), "0xcafef00d");
  r.unit = wire::SelfTestUnit::kSlot;
  r.mantissa = 2;
  EXPECT_EQ(SelfTestValueText(r), "damaged");
  r.unit = wire::SelfTestUnit::kBrownOut;
  r.mantissa = 4;
  EXPECT_EQ(SelfTestValueText(r), "level3");
  r.verdict = wire::SelfTestVerdict::kUnavailable;
  EXPECT_EQ(SelfTestValueText(r), "-");
  EXPECT_STREQ(SelfTestVerdictName(r.verdict), "unavailable");
  EXPECT_STREQ(SelfTestVerdictName(wire::SelfTestVerdict::kFail), "FAIL");
}

}  // namespace
TEST(HealthReport, TheClockLineSaysWhyTheBoardIsOnItsInternalOscillator) {
  wire::HealthInfoResponse h;
  EXPECT_FALSE(ClockText(h).has_value());  // the board does not say (emulator, QEMU image)
  h.clock = wire::ClockState::kCrystal;
  h.hse_measured_hz = 8000123;
  EXPECT_EQ(*ClockText(h), "crystal (measured 8.000 MHz against the internal oscillator)");
  h.clock = wire::ClockState::kCrystalWrongFrequency;
  h.hse_measured_hz = 12000340;
  EXPECT_EQ(*ClockText(h),
            "internal oscillator, acquisitions refused: the crystal measured 12.000 MHz, "
            "outside 95-109 % of the one the image was built for (the internal oscillator's "
            "spread over temperature); build it for this board "
            "(VIBID_BOARD or VIBID_HSE_HZ, docs/board.md)");
  h.clock = wire::ClockState::kCrystalDidNotStart;
  EXPECT_NE(ClockText(h)->find("did not start"), std::string::npos);
  EXPECT_STREQ(ClockStateName(3), "crystal-wrong-frequency");
  EXPECT_STREQ(ClockStateName(99), "unknown");
  EXPECT_STREQ(SelfTestReferenceName(wire::SelfTestReference::kLse), "lse");
  EXPECT_STREQ(SelfTestReferenceName(wire::SelfTestReference::kNone), "");
}

TEST(HealthReport, FaultRecordInWords) {
  // A BusFault with a precise bad address (CFSR BFARVALID bit 15, PRECISERR bit 9) escalated to
  // HardFault (HFSR FORCED bit 30): ARMv7-M ARM B3.2.15, B3.2.16.
  const wire::FaultInfoResponse f{.recorded = 1,
                                  .exception = 3,
                                  .cfsr = 0x00008200,
                                  .hfsr = 0x40000000,
                                  .mmfar = 0xE000EDF8,
                                  .bfar = 0x40026400,
                                  .pc = 0x08012345,
                                  .lr = 0x08011111};
  EXPECT_EQ(FaultText(f),
            "HardFault at pc 0x08012345, lr 0x08011111; CFSR 0x00008200, HFSR 0x40000000, BFAR "
            "0x40026400 (PRECISERR BFARVALID FORCED)");
  EXPECT_EQ(FaultStatusNames(f), (std::vector<std::string>{"PRECISERR", "BFARVALID", "FORCED"}));
  // UsageFault divide by zero (CFSR bit 25), no address register valid; stack not readable.
  const wire::FaultInfoResponse g{.recorded = 1,
                                  .exception = 6,
                                  .cfsr = 1u << 25,
                                  .pc = wire::kFaultNoStackedValue,
                                  .lr = wire::kFaultNoStackedValue};
  EXPECT_EQ(FaultText(g),
            "UsageFault with the stack outside RAM (no pc, lr); CFSR 0x02000000, HFSR 0x00000000 "
            "(DIVBYZERO)");
  EXPECT_EQ(FaultExceptionName(16 + 18), "IRQ 18 without a handler");
  EXPECT_STREQ(ResetCauseName(wire::ResetCause::kFault), "fault");
}

}  // namespace vibid::device
