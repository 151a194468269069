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
}  // namespace vibid::device
