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
            "internal oscillator, acquisitions refused: the crystal measured 12.000 MHz, more "
            "than 2 % from the one the image was built for; build it for this board "
            "(VIBID_BOARD or VIBID_HSE_HZ, docs/board.md)");
  h.clock = wire::ClockState::kCrystalDidNotStart;
  EXPECT_NE(ClockText(h)->find("did not start"), std::string::npos);
  EXPECT_STREQ(ClockStateName(3), "crystal-wrong-frequency");
  EXPECT_STREQ(ClockStateName(99), "unknown");
  EXPECT_STREQ(SelfTestReferenceName(wire::SelfTestReference::kLse), "lse");
  EXPECT_STREQ(SelfTestReferenceName(wire::SelfTestReference::kNone), "");
}

}  // namespace vibid::device
